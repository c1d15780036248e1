//! Issue 12: motions of the Panda (example-robot-data) among the bundled workcell's thin surfaces,
//! against an oracle that samples every motion densely: every point of the arm moves less than
//! 1 mm between samples (a bound of 1.2 m from any joint axis to any point of the arm downstream,
//! checked below). Each sample is checked by the discrete checker (itself proven against parry's GJK over
//! 500,000 pairs in tests/sat_oracle.rs); a near miss is measured with parry's GJK distance.
//!
//! For every motion:
//! - a motion with a colliding sample is never reported free;
//! - no colliding sample lies before the reported fraction minus one step;
//! - a motion reported colliding has a sample within `motion_tolerance` plus one step of the
//!   object it names (a colliding sample, or parry's distance from the link to the named cell, or
//!   to the named link of the robot: self pairs are part of the check, without an SRDF here, so
//!   adjacent pairs and those touching at the zero state are allowed).

mod common;

use oorandom::Rand64;
use thickness_collision::checker::Checker;
use thickness_collision::collision::TargetShape;

const REACH: f64 = 1.2;
const STEP: f64 = 1e-3;
const MOTIONS: usize = 2_000;

fn panda() -> Checker {
    Checker::from_params(common::panda_params()).unwrap()
}

#[test]
fn motions_agree_with_dense_sampling() {
    let c = panda();
    let robot = c.robot();
    // The bound the oracle's step rests on, in every configuration: from a joint's axis to a
    // point of a link downstream, at most the joint origins' distances along the chain plus the
    // point's distance from its link's origin.
    for t in c.targets() {
        let reach = t.parts.iter().map(|(shape, offset)| match shape {
            TargetShape::Polytope(h) => h.points().iter().map(|p| (*offset * *p).length()).fold(0.0, f64::max),
            other => panic!("Panda links are meshes, not {other:?}"),
        });
        let mut chain = reach.fold(0.0, f64::max);
        let mut link = t.link;
        while let Some(j) = robot.joints.iter().find(|j| j.child == link) {
            assert!(chain < REACH, "{} reaches {chain} m from joint {}", t.name, j.name);
            chain += j.origin.translation.vector.norm();
            link = j.parent;
        }
    }

    let arm: Vec<usize> = (1..=7).map(|i| robot.joint(&format!("panda_joint{i}")).unwrap()).collect();
    let mut rng = Rand64::new(12);
    let (mut colliding, mut free, mut near_misses, mut samples) = (0, 0, 0, 0usize);
    for m in 0..MOTIONS {
        let mut q0 = vec![0.0; robot.joints.len()];
        let mut q1 = q0.clone();
        for &j in &arm {
            let [lo, hi] = robot.joints[j].limits;
            let a = lo + (hi - lo) * rng.rand_float();
            let d = (0.05 + 0.45 * rng.rand_float()) * if rng.rand_u64().is_multiple_of(2) { 1.0 } else { -1.0 };
            q0[j] = a;
            q1[j] = (a + d).clamp(lo, hi);
        }
        let r = c.check_motion(&q0, &q1);
        assert!(r.report.error.is_empty(), "motion {m}: {}", r.report.error);
        let total: f64 = arm.iter().map(|&j| (q1[j] - q0[j]).abs()).sum();
        let n = ((REACH * total / STEP).ceil() as usize).max(1);
        samples += n + 1;
        let at = |s: f64| -> Vec<f64> { q0.iter().zip(&q1).map(|(a, b)| a + s * (b - a)).collect() };
        let first_hit = (0..=n).map(|k| k as f64 / n as f64).find(|&s| c.check_positions(&at(s)).unwrap().in_collision);
        if let Some(s) = first_hit {
            assert!(r.report.in_collision, "motion {m}: reported free, but the sample at s = {s} collides");
            let f = r.fraction.unwrap();
            assert!(s >= f - 1.0 / n as f64, "motion {m}: a colliding sample at {s}, before the reported fraction {f}");
        }
        if !r.report.in_collision {
            free += 1;
            continue;
        }
        colliding += 1;
        let f = r.fraction.unwrap();
        // The report checks only what blocked the motion there: a full check of that state finds
        // exactly its contacts (every other link and pair was cleared around it), the motion's
        // report adding at most the near miss of the link that blocked it (depth 0).
        let full = c.check_positions(&at(f)).unwrap();
        let key = |x: &thickness_collision::checker::ReportContact| (x.link_name.clone(), x.object_name.clone(), x.triangle, x.depth.to_bits());
        let mut extra: Vec<_> = r.report.contacts.iter().filter(|x| !full.contacts.iter().any(|y| key(x) == key(y))).collect();
        assert!(
            full.contacts.iter().all(|y| r.report.contacts.iter().any(|x| key(x) == key(y))),
            "motion {m}: the state at {f} has {:?}, the motion reports {:?}",
            full.contacts,
            r.report.contacts
        );
        assert!(extra.len() <= 1 && extra.pop().is_none_or(|x| x.depth == 0.0), "motion {m}: {:?} beyond the state's {:?}", r.report.contacts, full.contacts);
        assert_eq!(r.report.out_of_limits, full.out_of_limits);
        if first_hit.is_some_and(|s| s <= f + 2.0 / n as f64) {
            continue;
        }
        // A near miss: the named link came within the tolerance of the named object.
        near_misses += 1;
        let contact = r.report.contacts.first().unwrap_or_else(|| panic!("motion {m}: colliding without a contact"));
        let k0 = ((f * n as f64).floor() as usize).saturating_sub(1);
        let qs: Vec<Vec<f64>> = (k0..=(k0 + 3).min(n)).map(|k| at(k as f64 / n as f64)).collect();
        let nearest = common::near_miss::nearest_to_contact(&c, &contact.link_name, &contact.object_name, contact.triangle, &qs);
        let tol = c.params().motion_tolerance;
        assert!(
            nearest <= tol + STEP,
            "motion {m}: reported colliding at {f}, but {} stays {nearest} m from {} (tolerance {tol})",
            contact.link_name,
            contact.object_name
        );
    }
    eprintln!("{MOTIONS} Panda motions, {samples} oracle samples: {colliding} colliding ({near_misses} near misses), {free} free");
    assert!(colliding > MOTIONS / 10 && free > MOTIONS / 10, "the sample must have both outcomes");
}
