//! The world objects of a planning scene, kept as MoveIt's `PlanningScene` keeps them
//! (`moveit_core/planning_scene/src/planning_scene.cpp`, `processCollisionObjectMsg`, and
//! `collision_detection::World`): the operations on ids, poses and shape lists, over any shape
//! type. What a shape becomes for the checks (cells, a hull, a solid) is decided where the world
//! is turned into a scene, not here.

use crate::math::Pose;
use std::collections::BTreeMap;
use std::fmt;

/// One object: its pose in the world frame, its shapes with their poses relative to it (in the
/// order primitives, meshes, planes of the message that added them, appends after), and its
/// subframes (relative to it).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct WorldObject<S> {
    pub pose: Pose,
    pub shapes: Vec<(S, Pose)>,
    pub subframes: Vec<(String, Pose)>,
}

/// What `ADD` and `APPEND` carry, the frame already resolved: `header` is the pose of the
/// message's `header.frame_id` in the world, `pose` the message's object pose (`None` when it is
/// MoveIt's "empty" pose: zero position, identity orientation), `shapes` in the order primitives,
/// meshes, planes, each with its pose (identity where the message gives fewer poses than shapes).
pub(crate) struct AddObject<S> {
    pub header: Pose,
    pub pose: Option<Pose>,
    pub shapes: Vec<(S, Pose)>,
    pub subframes: Vec<(String, Pose)>,
}

/// Why an operation was not applied (the world is unchanged).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum WorldError {
    /// `ADD` or `APPEND` without a shape.
    NoShapes(String),
    /// `MOVE` or `REMOVE` of an id the world does not hold.
    Unknown(String),
    /// `MOVE` with shape poses whose number is not the object's number of shapes.
    ShapePoses { id: String, given: usize, shapes: usize },
}

impl fmt::Display for WorldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WorldError::NoShapes(id) => write!(f, "collision object '{id}': no primitives, meshes or planes to add"),
            WorldError::Unknown(id) => write!(f, "collision object '{id}': no such object in the planning scene"),
            WorldError::ShapePoses { id, given, shapes } => {
                write!(f, "collision object '{id}': MOVE gives {given} shape poses for {shapes} shapes (give all of them, or none)")
            }
        }
    }
}

/// The world objects by id (MoveIt keeps them in a map ordered by id, and so does this).
#[derive(Clone, Debug)]
pub(crate) struct PlanningWorld<S> {
    objects: BTreeMap<String, WorldObject<S>>,
}

impl<S> Default for PlanningWorld<S> {
    fn default() -> Self {
        PlanningWorld { objects: BTreeMap::new() }
    }
}

impl<S> PlanningWorld<S> {
    pub fn objects(&self) -> impl Iterator<Item = (&str, &WorldObject<S>)> {
        self.objects.iter().map(|(id, o)| (id.as_str(), o))
    }

    pub fn get(&self, id: &str) -> Option<&WorldObject<S>> {
        self.objects.get(id)
    }

    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// `ADD`: the object replaces any of the same id. With exactly one shape and an empty object
    /// pose, the shape's pose becomes the object's and the shape sits at its origin (MoveIt's
    /// reading of messages that only set the shape pose).
    pub fn add(&mut self, id: &str, add: AddObject<S>) -> Result<(), WorldError> {
        if add.shapes.is_empty() {
            return Err(WorldError::NoShapes(id.to_owned()));
        }
        let _ = self.objects.remove(id);
        self.append(id, add)
    }

    /// `APPEND`: the shapes join the object of that id, relative to its pose, which stays (the
    /// message's object pose only places a new object); subframes are replaced. An unknown id is
    /// a new object, as with `ADD`.
    pub fn append(&mut self, id: &str, add: AddObject<S>) -> Result<(), WorldError> {
        if add.shapes.is_empty() {
            return Err(WorldError::NoShapes(id.to_owned()));
        }
        let AddObject { header, pose, mut shapes, subframes } = add;
        let pose = match pose {
            Some(p) => p,
            None if shapes.len() == 1 => std::mem::replace(&mut shapes[0].1, Pose::IDENTITY),
            None => Pose::IDENTITY,
        };
        let object = self.objects.entry(id.to_owned()).or_insert_with(|| WorldObject { pose: header * pose, shapes: Vec::new(), subframes: Vec::new() });
        object.shapes.extend(shapes);
        object.subframes = subframes;
        Ok(())
    }

    /// `MOVE`: the object's pose becomes `header * pose`; with `shape_poses` (all of them, in the
    /// order of the object's shapes), the shapes move too. Geometry in the message is ignored.
    pub fn move_object(&mut self, id: &str, header: Pose, pose: Pose, shape_poses: Option<Vec<Pose>>) -> Result<(), WorldError> {
        let Some(object) = self.objects.get_mut(id) else {
            return Err(WorldError::Unknown(id.to_owned()));
        };
        if let Some(poses) = &shape_poses {
            if poses.len() != object.shapes.len() {
                return Err(WorldError::ShapePoses { id: id.to_owned(), given: poses.len(), shapes: object.shapes.len() });
            }
        }
        object.pose = header * pose;
        for ((_, p), new) in object.shapes.iter_mut().zip(shape_poses.into_iter().flatten()) {
            *p = new;
        }
        Ok(())
    }

    /// `REMOVE`: the object of that id, or every object for an empty id.
    pub fn remove(&mut self, id: &str) -> Result<(), WorldError> {
        if id.is_empty() {
            self.objects.clear();
            return Ok(());
        }
        self.objects.remove(id).map(|_| ()).ok_or_else(|| WorldError::Unknown(id.to_owned()))
    }

    /// Every shape with its pose in the world, object by object in id order.
    #[cfg(test)]
    pub fn shapes_in_world(&self) -> impl Iterator<Item = (&str, &S, Pose)> {
        self.objects.iter().flat_map(|(id, o)| o.shapes.iter().map(move |(s, p)| (id.as_str(), s, o.pose * *p)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Rotation, Vector};

    fn at(x: f64, y: f64, z: f64) -> Pose {
        Pose::from_translation(Vector::new(x, y, z))
    }

    fn add(pose: Option<Pose>, shapes: &[(&'static str, Pose)]) -> AddObject<&'static str> {
        AddObject { header: Pose::IDENTITY, pose, shapes: shapes.to_vec(), subframes: Vec::new() }
    }

    fn world_of(w: &PlanningWorld<&'static str>) -> Vec<(String, &'static str, [f64; 3])> {
        w.shapes_in_world().map(|(id, s, p)| (id.to_owned(), *s, p.translation.to_array().map(|x| (x * 1e9).round() / 1e9))).collect()
    }

    /// The operations as MoveIt applies them: ADD replaces, APPEND adds relative to the pose the
    /// object already has, MOVE sets the pose and (all or none) the shape poses, REMOVE by id or
    /// all; refusals leave the world as it was.
    #[test]
    fn operations_as_moveit_applies_them() {
        let mut w = PlanningWorld::default();
        w.add("shelf", add(Some(at(1.0, 0.0, 0.0)), &[("box", at(0.0, 0.0, 0.5)), ("mesh", at(0.0, 1.0, 0.0))])).unwrap();
        assert_eq!(world_of(&w), [("shelf".into(), "box", [1.0, 0.0, 0.5]), ("shelf".into(), "mesh", [1.0, 1.0, 0.0])]);
        // APPEND: the object keeps its pose (the message's object pose does not move it).
        w.append("shelf", add(Some(at(5.0, 5.0, 5.0)), &[("plane", at(0.0, 0.0, 1.0))])).unwrap();
        assert_eq!(w.get("shelf").unwrap().shapes.len(), 3);
        assert_eq!(world_of(&w)[2], ("shelf".into(), "plane", [1.0, 0.0, 1.0]));
        // ADD of the same id replaces it.
        w.add("shelf", add(Some(at(2.0, 0.0, 0.0)), &[("sphere", Pose::IDENTITY)])).unwrap();
        assert_eq!(world_of(&w), [("shelf".into(), "sphere", [2.0, 0.0, 0.0])]);
        // MOVE: pose relative to the header frame; shape poses all or none.
        let header = Pose::from_parts(Vector::new(0.0, 0.0, 1.0), Rotation::from_rotation_z(std::f64::consts::FRAC_PI_2));
        w.move_object("shelf", header, at(1.0, 0.0, 0.0), None).unwrap();
        assert_eq!(world_of(&w), [("shelf".into(), "sphere", [0.0, 1.0, 1.0])]);
        let before = world_of(&w);
        assert_eq!(
            w.move_object("shelf", Pose::IDENTITY, Pose::IDENTITY, Some(vec![])),
            Err(WorldError::ShapePoses { id: "shelf".into(), given: 0, shapes: 1 })
        );
        assert_eq!(w.move_object("ghost", Pose::IDENTITY, Pose::IDENTITY, None), Err(WorldError::Unknown("ghost".into())));
        assert_eq!(world_of(&w), before, "a refused MOVE changes nothing");
        w.move_object("shelf", Pose::IDENTITY, Pose::IDENTITY, Some(vec![at(0.0, 0.0, 3.0)])).unwrap();
        assert_eq!(world_of(&w), [("shelf".into(), "sphere", [0.0, 0.0, 3.0])]);
        // ADD without shapes, REMOVE of an unknown id: refused, nothing changes.
        assert_eq!(w.add("shelf", add(None, &[])), Err(WorldError::NoShapes("shelf".into())));
        assert_eq!(w.remove("ghost"), Err(WorldError::Unknown("ghost".into())));
        assert_eq!(w.len(), 1);
        w.add("guard", add(Some(Pose::IDENTITY), &[("mesh", Pose::IDENTITY)])).unwrap();
        w.remove("shelf").unwrap();
        assert_eq!(w.objects().map(|(id, _)| id).collect::<Vec<_>>(), ["guard"]);
        w.remove("").unwrap();
        assert_eq!(w.len(), 0, "REMOVE with an empty id removes every object");
    }

    /// One shape and an empty object pose: the shape's pose is the object's; with two shapes it
    /// stays the shapes' own.
    #[test]
    fn a_lone_shape_lends_its_pose_to_an_empty_object_pose() {
        let mut w = PlanningWorld::default();
        w.add("a", add(None, &[("box", at(0.5, 0.0, 0.0))])).unwrap();
        let a = w.get("a").unwrap();
        assert_eq!((a.pose.translation, a.shapes[0].1), (Vector::new(0.5, 0.0, 0.0), Pose::IDENTITY));
        w.add("b", add(None, &[("box", at(0.5, 0.0, 0.0)), ("sphere", at(0.0, 0.5, 0.0))])).unwrap();
        let b = w.get("b").unwrap();
        assert_eq!(b.pose, Pose::IDENTITY);
        assert_eq!(b.shapes[1].1.translation, Vector::new(0.0, 0.5, 0.0));
    }
}
