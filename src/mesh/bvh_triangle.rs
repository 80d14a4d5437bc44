//! A mesh's triangle as a leaf of the `bvh` crate's bounding volume hierarchy, with what its
//! user needs of the face beside the corners.

use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use nalgebra::Point3;

/// One triangle of a hierarchy: its corners, `data` of its face (the face's index, its
/// normal, ...) and the hierarchy's node index (set by [`bvh::bvh::Bvh::build`]).
pub(crate) struct BvhTriangle<T> {
    pub(crate) corners: [Point3<f64>; 3],
    pub(crate) data: T,
    node: usize,
}

impl<T> BvhTriangle<T> {
    /// Face `f` of `mesh` with `data`.
    pub(crate) fn new(mesh: &super::TriMesh, f: usize, data: T) -> Self {
        Self {
            corners: mesh.corners(f).map(|p| Point3::new(p[0], p[1], p[2])),
            data,
            node: 0,
        }
    }
}

impl<T> Bounded<f64, 3> for BvhTriangle<T> {
    fn aabb(&self) -> Aabb<f64, 3> {
        Aabb::empty()
            .grow(&self.corners[0])
            .grow(&self.corners[1])
            .grow(&self.corners[2])
    }
}

impl<T> BHShape<f64, 3> for BvhTriangle<T> {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}
