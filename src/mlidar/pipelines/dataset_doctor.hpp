#pragma once
// `mlidar doctor`: checks a dataset or bag before a long run and says, per
// check, what would fail or go wrong and how to fix it. It reads every frame
// through the same io::FrameSource the jobs use, so a file a job would reject
// (a lying header, times off by a unit, a truncated cloud) is found here with
// the same message; then it looks at what reads fine but would mislead a run:
// gaps in the stamps, scans skipped, per-point times that cover too little of
// a sweep, rings that do not match the model, extrinsics that are missing or
// implausible, LiDARs that hardly overlap the base at their given extrinsic,
// and whether the base turns enough, about enough axes, for hand-eye (doctor_motion.hpp).
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mlidar/io/bag_frames.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/pipelines/doctor_motion.hpp"

namespace mlidar::pipelines {

enum class Severity : std::uint8_t { kOk, kWarning, kFailure };
const char* to_string(Severity severity);  ///< "ok", "warning", "failure"

struct Finding {
  std::string check;  ///< "open", "stamps", "scans", "time", "rings", "extrinsics", "overlap", "motion"
  std::string lidar;  ///< empty when the check is not about one LiDAR
  Severity severity = Severity::kOk;
  std::string message;  ///< what was seen and, unless ok, what to do
};

struct DoctorConfig {
  double gap_ratio = 2.5;           ///< a stamp step over this x the median is a gap
  double min_time_coverage = 0.5;   ///< per-point times should span this share of a sweep at least
  double max_translation_m = 20.0;  ///< an extrinsic farther from the base is implausible on one vehicle
  double overlap_radius_m = 0.5;    ///< a point overlaps when a base point lies this close
  double min_overlap = 0.05;        ///< below this share of a LiDAR's points the overlap is too small
  std::size_t max_listed = 5;       ///< frames named in one message
  bool check_motion = true;         ///< run the base's odometry for the motion check
  MotionCheckConfig motion;
};

/// The findings for `source`, every check in the order above. Never throws for
/// bad data (each problem is a finding); opening the source is the caller's
/// (doctor_open turns its error into a finding).
std::vector<Finding> examine(const io::FrameSource& source, const DoctorConfig& config = {});

/// True when some finding is a failure (the command's exit 1).
bool has_failure(const std::vector<Finding>& findings);

/// `mlidar doctor INPUT`: a dataset folder or a bag (with `bag`'s topics and files) opened and examined; an input
/// that cannot be opened is one failure finding ("open"), as every job would stop there.
std::vector<Finding> examine_input(const std::filesystem::path& input, io::BagArguments bag, const DoctorConfig& config = {});

/// `doctor --json`'s document: {input, failed, findings: [{check, lidar, severity, message}]}.
nlohmann::json doctor_json(const std::string& input, const std::vector<Finding>& findings);

}  // namespace mlidar::pipelines
