#include "mlidar/sim/rig.hpp"

#include "mlidar/core/conversions.hpp"

#include <numbers>

#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/sim/lidar_models.hpp"

namespace mlidar::sim {
namespace {

SimLidar mount(const std::string& name, const std::string& model, const Vec3& t, const Vec3& rpy_deg, double sweep_offset = 0.0) {
  SimLidar lidar;
  lidar.name = name;
  lidar.model = lidar_model(model);
  lidar.T_base_lidar = SE3(quat_from_rpy_deg(rpy_deg), t);
  lidar.dropout_probability = 0.002;
  lidar.sweep_offset = sweep_offset;
  return lidar;
}

}  // namespace

std::vector<std::string> rig_names() { return {"rhd", "rv", "lyft", "single-vlp16", "single-hdl64"}; }

SimRig named_rig(const std::string& name) {
  SimRig rig;
  rig.name = name;
  if (name == "rhd") {
    rig.base_frame = "left";
    rig.base_height = 1.3;
    rig.lidars = {mount("left", "VLP-16", Vec3::Zero(), Vec3::Zero()),
                  mount("right", "VLP-16", Vec3(0.0, -0.477, -0.220), Vec3(40.0, 0.0, 0.0))};
  } else if (name == "rv") {
    rig.base_frame = "top";
    rig.base_height = 1.95;
    rig.lidars = {mount("top", "RS-LiDAR-16", Vec3::Zero(), Vec3::Zero()),
                  mount("front", "RS-LiDAR-16", Vec3(0.795, 0.0, -1.364), Vec3(0.0, 10.0, 0.0)),
                  mount("left", "RS-LiDAR-16", Vec3(0.3, 0.85, -0.95), Vec3(-15.0, 0.0, 0.0)),
                  mount("right", "RS-LiDAR-16", Vec3(0.3, -0.85, -0.95), Vec3(15.0, 0.0, 0.0))};
  } else if (name == "lyft") {
    rig.base_frame = "vehicle";
    rig.base_height = 0.0;
    rig.lidars = {mount("top", "HDL-64E", Vec3(1.197, 0.0, 1.828), Vec3::Zero()),
                  mount("front_left", "PandarQT", Vec3(3.473, 0.942, 0.543), Vec3(0.0, 0.0, 45.0), 0.025),
                  mount("front_right", "PandarQT", Vec3(3.498, -0.950, 0.547), Vec3(0.0, 0.0, -45.0), 0.05)};
  } else if (name == "single-vlp16" || name == "single-hdl64") {
    rig.base_frame = "lidar";
    rig.base_height = 1.8;
    rig.lidars = {mount("lidar", name == "single-vlp16" ? "VLP-16" : "HDL-64E", Vec3::Zero(), Vec3::Zero())};
  } else {
    throw UsageError("unknown rig '" + name + "' (known: rhd, rv, lyft, single-vlp16, single-hdl64, or a rig .yaml file)");
  }
  return rig;
}

SimRig load_rig(const std::string& name_or_path) {
  const std::filesystem::path path(name_or_path);
  const bool looks_like_file = path.extension() == ".yaml" || path.extension() == ".yml";
  if (looks_like_file || std::filesystem::is_regular_file(path)) {
    return parse_rig_yaml(io::read_file_text(path), name_or_path);
  }
  return named_rig(name_or_path);
}

}  // namespace mlidar::sim
