//! Collision of convex robot links ("targets") with thickness cells.
//!
//! The narrow phase is a separating-axis test, as in the claim: project both shapes on an axis,
//! and if `Amax <= Bmin` or `Bmax <= Amin` on any axis they are apart (touching is not a
//! collision). The candidate axes make the test exact:
//! - convex polytopes (boxes, mesh hulls): the face normals of both, and the cross products of
//!   edge pairs that form a face of the Minkowski difference (the Gauss-map test of Gregorius,
//!   GDC 2013), which prunes the `E_a x E_b` pairs to the few that matter;
//! - spheres and capsules: the cell's face normals, the cross products of the capsule's axis with
//!   the cell's edges, and the closest-feature directions (vertex and edge to the sphere centre or
//!   the capsule's segment), which cover every face, edge and vertex of the Minkowski difference;
//! - cylinders have no finite exact axis set: they are decided with parry's GJK/EPA.
//!
//! The broad phase is a BVH over each object's cells whose nodes also bound the cells' normals
//! (`cell_tree`), so the deepest contact is found without visiting every cell under a link. What
//! is reported is in `report`.

mod cell_contact;
mod cell_search;
mod cell_slab;
mod cell_tree;
mod cell_walk;
mod collector;
mod contact_point;
mod convex_hull;
mod gjk;
mod pair;
mod polytope;
mod report;
mod sat;
mod scene;
mod scene_ball;
pub(crate) use self::scene_ball::BallWitness;
mod scene_clearance;
mod target;
mod target_view;

pub use self::cell_contact::{collide_target_cell, CellHit};
pub use self::cell_tree::CellTree;
pub use self::convex_hull::ConvexHull;
pub(crate) use self::pair::{collide_pair, pair_may_meet_grown, PairContact};
pub use self::report::{CollideSettings, Contact, LeastOverlap, TargetReport};
pub use self::scene::{ObjectBody, Scene, SceneObject};
pub use self::scene_clearance::Clearance;
pub use self::target::{Target, TargetShape};
