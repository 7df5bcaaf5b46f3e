#pragma once
// Ground truth in the base frame at a frame stamp.
//
// Boxes (groundtruth/boxes/NNNNNN.txt) use the KITTI label_2 text layout
// (io::KittiObject, 15 columns) with these conventions, NOT KITTI's camera frame:
//   location    = centre of the box's bottom face in the base frame (x y z, metres)
//   dimensions  = height width length (metres); length lies along the heading
//   rotation_y  = heading: angle of the length axis projected on the base
//                 x-y plane, counter-clockwise from base +x about base +z (rad);
//                 exact when base z is vertical (planar trajectories)
//   alpha       = rotation_y - atan2(location.y, location.x), wrapped to (-pi, pi]
//   truncated = 0, occluded = 0, bbox = 0 0 0 0 (no camera)
// The object ids (1-based, stable across frames) are written one per line in
// the same order to groundtruth/boxes/NNNNNN.ids, since label_2 has no id column.
// Only objects hit by at least one point of the frame are listed.
#include <set>
#include <vector>

#include "mlidar/io/kitti.hpp"
#include "mlidar/sim/scene.hpp"

namespace mlidar::sim {

/// The object's box at time t, as seen from the base at pose T_world_base.
io::KittiObject box_in_base(const LabelledObject& object, double t, const SE3& T_world_base);

/// True when the base-frame point p lies inside the box (grown by margin).
bool box_contains(const io::KittiObject& box, const Vec3& p_base, double margin);

}  // namespace mlidar::sim
