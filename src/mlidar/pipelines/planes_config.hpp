#pragma once
// planes.yaml: the PlanesConfig keys with their C++ names, all optional.
#include <string>

#include "mlidar/calib/planes_types.hpp"

namespace mlidar::pipelines {

/// Unknown keys or values of the wrong type throw UsageError naming file and key;
/// out-of-range values are reported by PlanesConfig::validate.
calib::PlanesConfig parse_planes_config(const std::string& yaml_text, const std::string& source);

}  // namespace mlidar::pipelines
