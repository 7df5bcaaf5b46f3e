#pragma once
// The files `mlidar calibrate auto` writes (layout in autocalib_job.hpp):
// RUN/extrinsics.yaml and RUN/calibration.json, each atomically.
#include <nlohmann/json.hpp>

#include "mlidar/pipelines/autocalib_job.hpp"

namespace mlidar::pipelines {

void write_autocalib_outputs(const AutoCalibJob& job, const AutoCalibSummary& summary, const nlohmann::json& skipped_scans);

}  // namespace mlidar::pipelines
