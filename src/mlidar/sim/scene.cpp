#include "mlidar/sim/scene.hpp"

#include <cmath>

namespace mlidar::sim {

bool LabelledObject::contains(const Vec3& p, double t, double margin) const {
  const Vec3 local = Eigen::AngleAxisd(-yaw, Vec3::UnitZ()) * (p - centre_at(t));
  return (local.array().abs() <= (0.5 * size).array() + margin).all();
}

Scene::Scene(std::string name, const std::vector<Primitive>& primitives, std::vector<LabelledObject> objects, double cell_size)
    : name_(std::move(name)), objects_(std::move(objects)) {
  std::vector<Primitive> gridded;
  for (const auto& p : primitives) {
    if (!is_bounded(p)) {
      unbounded_.push_back(p);
    } else if (p.velocity.squaredNorm() > 0.0) {
      moving_.push_back(p);
    } else {
      gridded.push_back(p);
    }
  }
  grid_ = UniformGrid(std::move(gridded), cell_size);
}

std::optional<Hit> Scene::cast(const Ray& ray, double t_min, double t_max, double time) const {
  std::optional<Hit> best;
  double limit = t_max;
  auto keep = [&](const std::optional<Hit>& hit) {
    if (hit) {
      best = hit;
      limit = hit->t;
    }
  };
  for (const auto& p : unbounded_) keep(intersect(p, ray, t_min, limit));
  for (const auto& p : moving_) keep(intersect(p.at_time(time), ray, t_min, limit));
  keep(grid_.cast(ray, t_min, limit));
  return best;
}

std::vector<Primitive> Scene::primitives() const {
  std::vector<Primitive> all = unbounded_;
  all.insert(all.end(), moving_.begin(), moving_.end());
  all.insert(all.end(), grid_.primitives().begin(), grid_.primitives().end());
  return all;
}

Primitive object_box(const LabelledObject& object, double reflectivity) {
  Primitive box = make_box(object.centre, object.yaw, 0.5 * object.size, reflectivity, object.id);
  box.velocity = object.velocity;
  return box;
}

}  // namespace mlidar::sim
