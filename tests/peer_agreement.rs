//! A small version of the peer benchmark (benches/peer_compare.rs): the Panda against a
//! 10,000-triangle world of thin surfaces, 300 random states; every link-level disagreement with
//! coal and python-fcl must be explained (ours reports a link that reaches less than the thickness
//! behind a surface, confirmed by parry's GJK on hull and cell; or the link is within 1e-6 m of
//! touching).

#[path = "../benches/peer_compare_core.rs"]
mod peer_compare_core;

use peer_compare_core::*;

#[test]
fn no_unexplained_disagreement_with_coal_and_fcl() {
    let py = python();
    let (robot, map) = panda(&py);
    let states = random_states(&robot, 300, 1);
    let dir = scaffold::scratch_dir("peer_agreement");
    let c = compare(&py, &robot, &map, &states, 10_000, &dir);
    eprintln!(
        "{} triangles, {} states: ours colliding {}, coal {}; explained by thickness {}, by touching {}; unexplained {}",
        c.triangles,
        c.states,
        c.ours_colliding_states,
        c.coal_colliding_states,
        c.explained_thickness,
        c.explained_touching,
        c.unexplained.len()
    );
    for u in &c.unexplained {
        eprintln!("  {u}");
    }
    assert!(c.ours_colliding_states > 0 && c.coal_colliding_states > 0);
    assert!(c.unexplained.is_empty(), "{} unexplained disagreements", c.unexplained.len());
}
