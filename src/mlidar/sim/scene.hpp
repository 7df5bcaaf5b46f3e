#pragma once
// A scene: analytic primitives ray-cast exactly. Static bounded primitives sit
// in a uniform grid, unbounded ones (ground) and moving ones are tested for
// every ray (moving ones at the ray's time). Labelled objects (cars,
// pedestrians) are oriented boxes with a class, an id and a velocity.
#include <optional>
#include <string>
#include <vector>

#include "mlidar/sim/primitives.hpp"
#include "mlidar/sim/uniform_grid.hpp"

namespace mlidar::sim {

/// A labelled box in the world frame: centre of the box at time 0, size
/// (length along the heading, width, height), heading yaw about world z.
struct LabelledObject {
  int id = 0;
  std::string type;  ///< KITTI class name: "Car", "Pedestrian"
  Vec3 centre = Vec3::Zero();
  Vec3 size = Vec3::Zero();
  double yaw = 0.0;
  Vec3 velocity = Vec3::Zero();

  Vec3 centre_at(double t) const { return centre + velocity * t; }
  /// True when world point p lies in the box at time t, grown by margin metres.
  bool contains(const Vec3& p, double t, double margin) const;
};

class Scene {
 public:
  Scene() = default;
  /// Primitives with object_id >= 0 must refer to an entry of objects.
  Scene(std::string name, const std::vector<Primitive>& primitives, std::vector<LabelledObject> objects, double cell_size = 2.0);

  /// Nearest hit in (t_min, t_max] with moving primitives placed at `time`.
  std::optional<Hit> cast(const Ray& ray, double t_min, double t_max, double time) const;

  const std::string& name() const { return name_; }
  const std::vector<LabelledObject>& objects() const { return objects_; }
  /// Every primitive (static, moving and unbounded), for tests and tools.
  std::vector<Primitive> primitives() const;

 private:
  std::string name_;
  std::vector<Primitive> unbounded_;
  std::vector<Primitive> moving_;
  UniformGrid grid_;
  std::vector<LabelledObject> objects_;
};

/// A box primitive for a labelled object, moving with it.
Primitive object_box(const LabelledObject& object, double reflectivity);

}  // namespace mlidar::sim
