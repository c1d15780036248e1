//! Consistent winding per connected component.
//!
//! A breadth-first flood over shared edges decides, for every face, whether to flip it relative to
//! the component's first face. The component's overall sense is then chosen: outward (positive
//! signed volume) when it is closed, otherwise the sense of the larger total area, so that a sheet
//! drawn mostly one way keeps that front. Shared edges whose faces still disagree afterwards are
//! non-orientable seams (a Moebius strip has one) and are counted.

use super::mesh_topology::{EdgeLink, MeshTopology};
use crate::math::Real;
use std::collections::VecDeque;

pub(super) fn orient(mesh: &mut MeshTopology) {
    let n = mesh.triangles.len();
    let mut component = vec![u32::MAX; n];
    let mut flip = vec![false; n];
    let mut closed = Vec::new();
    let mut queue = VecDeque::new();
    for seed in 0..n {
        if component[seed] != u32::MAX {
            continue;
        }
        let id = closed.len() as u32;
        component[seed] = id;
        queue.push_back(seed);
        let (members, is_closed) = flood(mesh, id, &mut component, &mut flip, &mut queue);
        if should_invert(mesh, &members, &flip, is_closed) {
            for &f in &members {
                flip[f] = !flip[f];
            }
        }
        closed.push(is_closed);
    }
    let (flipped, inconsistent) = apply_flips(mesh, &flip);
    mesh.report.flipped_faces = flipped;
    mesh.report.inconsistent_edges = inconsistent;
    mesh.report.closed_components = closed.iter().filter(|&&c| c).count();
    mesh.report.open_components = closed.len() - mesh.report.closed_components;
    mesh.component = component;
    mesh.component_closed = closed;
}

/// The faces reached from those in `queue` over shared edges, each given component `id` and its
/// flip relative to the face it was reached from; and whether the component has no open edge.
fn flood(mesh: &MeshTopology, id: u32, component: &mut [u32], flip: &mut [bool], queue: &mut VecDeque<usize>) -> (Vec<usize>, bool) {
    let mut members = Vec::new();
    let mut is_closed = true;
    while let Some(f) = queue.pop_front() {
        members.push(f);
        for link in mesh.links[f] {
            match link {
                EdgeLink::Shared { face, consistent } => {
                    let g = face as usize;
                    if component[g] == u32::MAX {
                        component[g] = id;
                        flip[g] = flip[f] ^ !consistent;
                        queue.push_back(g);
                    }
                }
                _ => is_closed = false,
            }
        }
    }
    (members, is_closed)
}

/// Whether a component, after its relative flips, faces the wrong way: inward (negative signed
/// volume) when closed, else with more of its area flipped than kept.
fn should_invert(mesh: &MeshTopology, members: &[usize], flip: &[bool], is_closed: bool) -> bool {
    let mut volume = 0.0;
    let mut kept_area = 0.0;
    let mut flipped_area = 0.0;
    for &f in members {
        let [a, b, c] = mesh.triangles[f].map(|i| mesh.vertices[i as usize]);
        let s: Real = if flip[f] { -1.0 } else { 1.0 };
        volume += s * a.dot(b.cross(c));
        let area = (b - a).cross(c - a).length();
        if flip[f] {
            flipped_area += area;
        } else {
            kept_area += area;
        }
    }
    if is_closed {
        volume < 0.0
    } else {
        flipped_area > kept_area
    }
}

/// Flips the faces marked in `flip` and updates every shared edge's consistency; returns the
/// faces flipped and the shared edges whose faces still disagree (each counted once).
fn apply_flips(mesh: &mut MeshTopology, flip: &[bool]) -> (usize, usize) {
    let n = mesh.triangles.len();
    let mut flipped = 0;
    for f in 0..n {
        if flip[f] {
            flipped += 1;
            mesh.triangles[f].swap(1, 2);
            // Edge i of [a, c, b] is edge 2 - i of [a, b, c], reversed.
            mesh.links[f].swap(0, 2);
        }
    }
    let mut inconsistent = 0;
    for f in 0..n {
        for link in mesh.links[f].iter_mut() {
            if let EdgeLink::Shared { face, consistent } = link {
                let g = *face as usize;
                *consistent ^= flip[f] ^ flip[g];
                if !*consistent && f < g {
                    inconsistent += 1;
                }
            }
        }
    }
    (flipped, inconsistent)
}
