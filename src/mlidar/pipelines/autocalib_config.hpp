#pragma once
// auto.yaml: the stage parameters of `mlidar calibrate auto`, every key optional
// (the defaults are AutoCalibJob's):
//   pair_stride: 5                 # frames between the ends of a motion pair
//   ground_frames: 10              # frames used for the ground planes
//   handeye:
//     screw_angle_tolerance_rad: 0.01   # eq 3.4
//     screw_pitch_tolerance_m: 0.02     # eq 3.4
//     planar_singular_ratio: 0.05       # s3 / s1 below: planar motion
//   refine:
//     frame_step: 5                # a candidate every this many frames
//     window: 3                    # base local map: frames k - window .. k + window
//     overlap_radius_m: 2.0        # eq 3.13's r
//     min_overlap: 0.05            # eq 3.14: absolute floor on Omega
//     relative_overlap: 0.8        # eq 3.14's 0.8, times the best frame's Omega
//     coarse_correspondence_m: 1.0
//     fine_correspondence_m: 0.3
//     min_match_ratio: 0.3
//     min_candidates: 3            # fewer registrations: verdict too_few_candidates
//     keep_fraction: 0.2           # best candidates kept by registration error
//     min_keep: 5
// Unknown keys and bad values are InputErrors naming the file and the key.
#include <string>

#include "mlidar/pipelines/autocalib_job.hpp"

namespace mlidar::pipelines {

/// Returns `job` with the keys of `yaml_text` applied; `source` names the file in errors.
AutoCalibJob apply_autocalib_config(const std::string& yaml_text, const std::string& source, AutoCalibJob job);

}  // namespace mlidar::pipelines
