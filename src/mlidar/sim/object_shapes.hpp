#pragma once
// Labelled objects built from several primitives, so that their points are not
// those of a box: a car is a body, a cabin and four wheels; a pedestrian two
// legs, a torso, two arms and a head; a cyclist a bicycle (two wheels, a frame,
// handlebars) and a rider. Parts are laid out in the object's own frame
// (x along the heading, y to its left, z up from the ground); the label is the
// tightest upright box around every part.
#include <random>
#include <string>
#include <vector>

#include "mlidar/io/detection_labels.hpp"
#include "mlidar/sim/primitives.hpp"
#include "mlidar/sim/scene.hpp"

namespace mlidar::sim {

/// The detection classes, as `eval detections` reads them.
using io::ObjectClass;

/// KITTI's class name: "Car", "Pedestrian", "Cyclist" (label_2 files; io::object_class_name is lowercase).
std::string kitti_class_name(ObjectClass object_class);

/// An object of one class with its parts, placed on the ground.
struct ShapedObject {
  LabelledObject label;          ///< the tight box (centre, size l w h, yaw); type = kitti_class_name
  std::vector<Primitive> parts;  ///< world frame, each with object_id = label.id
};

/// A randomly sized object of `object_class` standing at `origin` (world frame: the point on the ground under the
/// object's reference point; the label's bottom is at origin.z) with heading yaw (rad about world z), labelled `id` (> 0). Sizes:
/// cars 3.6-5.2 m long, 1.6-2.0 m wide, 1.4-1.9 m high; pedestrians 1.5-1.95 m tall; cyclists 1.6-1.9 m long, 1.5-1.9 m high.
ShapedObject make_shaped_object(ObjectClass object_class, const Vec3& origin, double yaw, int id, std::mt19937_64& rng);

}  // namespace mlidar::sim
