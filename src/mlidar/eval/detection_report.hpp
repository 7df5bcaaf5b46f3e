#pragma once
// JSON and text renderings of `mlidar eval detections` (eval/detection_ap.hpp). The JSON keys are a public
// interface (the README lists them): add keys, never rename them. AP values are in percent, as the KITTI devkit
// prints them; a difficulty without ground truth has AP null.
//
//   {"frames", "difficulty_range_m": {"easy": 20, "moderate": 30, "hard": 50},
//    "classes": {CLASS: {"ground_truths", "predictions",
//                        "strict" | "loose": {"iou", DIFFICULTY: {"ground_truths", "3d": AP, "bev": AP}}}},
//    "mean": {"strict" | "loose": {DIFFICULTY: {"classes", "3d": {"ap_r40", "ap_r11"}, "bev": {"ap_r40", "ap_r11"}}}}}
//   AP = {"ap_r40", "ap_r11", "true_positives", "false_positives", "precision_r40": [40 interpolated precisions, 0-1]}
//   CLASS = car | pedestrian | cyclist (those evaluated); DIFFICULTY = easy | moderate | hard
#include <string>

#include <nlohmann/json.hpp>

#include "mlidar/eval/detection_ap.hpp"

namespace mlidar::eval {

nlohmann::json to_json(const DetectionEvalResult& result);

/// One row per class and difficulty (ground truths; 3D R40, 3D R11, BEV R40 at the strict and the loose IoU),
/// then the means.
std::string format_table(const DetectionEvalResult& result);

}  // namespace mlidar::eval
