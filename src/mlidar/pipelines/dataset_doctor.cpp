#include "mlidar/pipelines/dataset_doctor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/core/median.hpp"
#include "mlidar/geometry/kdtree.hpp"
#include "mlidar/pipelines/doctor_motion.hpp"
#include "mlidar/pipelines/frame_gaps.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/slam/row_recovery.hpp"

namespace mlidar::pipelines {
namespace {

std::string number(double value, const char* format = "%.3g") {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string frame_list(const std::vector<std::size_t>& frames, std::size_t max_listed) {
  std::string out;
  for (std::size_t i = 0; i < frames.size() && i < max_listed; ++i) out += (i ? ", " : "") + std::to_string(frames[i]);
  if (frames.size() > max_listed) out += ", ... (" + std::to_string(frames.size()) + " in all)";
  return out;
}

void check_stamps(const io::FrameSource& source, const DoctorConfig& config, std::vector<Finding>& out) {
  const std::vector<double>& stamps = source.stamps();
  if (stamps.size() < 2) {
    out.push_back({"stamps", "", Severity::kFailure, std::to_string(stamps.size()) + " frame(s): a run needs at least 2"});
    return;
  }
  std::vector<double> steps;
  for (std::size_t k = 1; k < stamps.size(); ++k) steps.push_back(stamps[k] - stamps[k - 1]);
  const double typical = upper_median(steps);
  std::vector<std::size_t> gaps;
  for (std::size_t k = 0; k < steps.size(); ++k)
    if (steps[k] > config.gap_ratio * typical) gaps.push_back(k + 1);
  const std::string span = std::to_string(stamps.size()) + " frames over " + number(stamps.back() - stamps.front(), "%.1f") +
                           " s, median step " + number(typical) + " s";
  if (gaps.empty()) {
    out.push_back({"stamps", "", Severity::kOk, span});
  } else {
    out.push_back({"stamps", "", Severity::kWarning,
                   span + "; " + std::to_string(gaps.size()) + " gap(s) over " + number(config.gap_ratio, "%.1f") +
                       "x the median before frame(s) " + frame_list(gaps, config.max_listed) +
                       ": the motion across a gap is extrapolated; cut the recording there or expect those frames to be suspect"});
  }
}

/// What one LiDAR's scans looked like over the whole source.
struct LidarTally {
  std::size_t scans = 0;
  std::size_t timed = 0;
  double min_time_span = std::numeric_limits<double>::infinity();
  std::size_t with_ring = 0;
  std::size_t max_ring = 0;
  std::map<std::string, std::vector<std::size_t>> skipped;  ///< reason -> frames
  std::optional<Scan> first;                                ///< the first scan, for the overlap
};

void tally_scan(const Scan& scan, LidarTally& t) {
  ++t.scans;
  if (!t.first) t.first = scan;
  if (!scan.time.empty()) {
    ++t.timed;
    const auto [lo, hi] = std::minmax_element(scan.time.begin(), scan.time.end());
    t.min_time_span = std::min(t.min_time_span, static_cast<double>(*hi - *lo));
  }
  if (scan.has_ring()) {
    ++t.with_ring;
    t.max_ring = std::max<std::size_t>(t.max_ring, *std::max_element(scan.ring.begin(), scan.ring.end()));
  }
}

/// Reads every frame; a frame the jobs would reject is a failure naming it. The base's scans also go to `motion`.
std::vector<LidarTally> read_all(const io::FrameSource& source, const DoctorConfig& config, std::optional<BaseMotion>& motion,
                                 std::vector<Finding>& out) {
  const std::optional<std::size_t> base = source.reference_index();
  std::vector<LidarTally> tallies(source.lidars().size());
  std::vector<std::string> rejected;
  std::size_t rejected_frames = 0;
  for (std::size_t k = 0; k < source.frames(); ++k) {
    try {
      const io::SourceFrame frame = source.read(k);
      for (std::size_t j = 0; j < frame.scans.size(); ++j)
        if (frame.scans[j]) tally_scan(*frame.scans[j], tallies[j]);
      for (const io::SkippedScan& s : frame.skipped) tallies[s.lidar].skipped[io::to_string(s.reason)].push_back(k);
      if (motion && base) motion->add(frame.stamp, frame.scans[*base]);
    } catch (const std::exception& error) {  // InputError naming the file and field, as the jobs would stop with
      if (rejected.size() < config.max_listed) rejected.push_back("frame " + std::to_string(k) + ": " + error.what());
      ++rejected_frames;
    }
  }
  if (rejected_frames > 0) {
    std::string text = std::to_string(rejected_frames) + " frame(s) a job would stop at (exit 3):";
    for (const std::string& r : rejected) text += "\n  " + r;
    out.push_back({"scans", "", Severity::kFailure, text});
  }
  return tallies;
}

void check_scans(const io::FrameSource& source, const std::vector<LidarTally>& tallies, const DoctorConfig& config,
                 std::vector<Finding>& out) {
  const std::optional<std::size_t> base = source.reference_index();
  for (std::size_t j = 0; j < tallies.size(); ++j) {
    const std::string& name = source.lidars()[j].name;
    const LidarTally& t = tallies[j];
    std::size_t missing = 0;
    std::string reasons;
    for (const auto& [reason, frames] : t.skipped) {
      missing += frames.size();
      reasons += (reasons.empty() ? "" : "; ") + std::to_string(frames.size()) + " " + reason + " (frame " +
                 frame_list(frames, config.max_listed) + ")";
    }
    const double share = source.frames() ? static_cast<double>(missing) / static_cast<double>(source.frames()) : 0.0;
    if (missing == 0) {
      out.push_back({"scans", name, Severity::kOk, std::to_string(t.scans) + " scans, all usable"});
    } else if (base && j == *base && share > kDefaultMaxBaseGaps) {
      out.push_back({"scans", name, Severity::kFailure,
                     "the base LiDAR lacks a usable scan in " + std::to_string(missing) + " of " + std::to_string(source.frames()) +
                         " frames: " + reasons + ". Jobs stop above " + number(100 * kDefaultMaxBaseGaps, "%.0f") +
                         " % (--max-base-gaps); fix or drop those scans, or choose another base"});
    } else {
      out.push_back({"scans", name, Severity::kWarning,
                     std::to_string(missing) + " of " + std::to_string(source.frames()) + " frames without a usable scan: " + reasons +
                         "; the run carries on without them"});
    }
  }
}

/// Where a LiDAR without a model gets its rows from, judged on its first scan (slam/frontend.hpp).
std::string rows_without_model(const LidarTally& t) {
  if (t.with_ring > 0)
    return "no model: " + std::to_string(t.max_ring + 1) + " rings from the ring field, their angles measured from the points";
  const auto rows = t.first ? slam::recover_rows(t.first->points) : std::nullopt;
  if (rows)
    return "no model and no ring field: the first scan shows " + std::to_string(rows->model.rings()) +
           " scan rows (recovered from its elevations for the range-image front end; scans that show none use voxel samples)";
  return "no model and no ring field, and the first scan shows no scan rows (a solid-state scanner, or sweeps merged while moving): "
         "0.5 m voxel samples serve as features";
}

void check_times_and_rings(const io::FrameSource& source, const std::vector<LidarTally>& tallies, const DoctorConfig& config,
                           std::vector<Finding>& out) {
  for (std::size_t j = 0; j < tallies.size(); ++j) {
    const io::SourceLidar& lidar = source.lidars()[j];
    const LidarTally& t = tallies[j];
    if (t.scans == 0) continue;
    const double sweep = lidar.model.sweep_period > 0.0 ? lidar.model.sweep_period : source.period();
    if (t.timed == 0) {
      out.push_back({"time", lidar.name, Severity::kWarning,
                     "no per-point time field (t, time, timestamp, offset_time): the scans are not deskewed, so motion during a sweep "
                     "blurs them; export the driver's point times if it has them"});
    } else if (t.timed < t.scans) {
      out.push_back({"time", lidar.name, Severity::kWarning,
                     std::to_string(t.scans - t.timed) + " of " + std::to_string(t.scans) + " scans without per-point times"});
    } else if (t.min_time_span < config.min_time_coverage * sweep) {
      out.push_back({"time", lidar.name, Severity::kWarning,
                     "per-point times span as little as " + number(t.min_time_span) + " s of a " + number(sweep) +
                         " s sweep: a wrong unit (time_unit in dataset.yaml) or a driver that stamps packets, not points"});
    } else {
      out.push_back({"time", lidar.name, Severity::kOk,
                     "per-point times span at least " + number(t.min_time_span) + " s of a " + number(sweep) + " s sweep"});
    }
    const std::size_t rows = lidar.model.rings();
    if (rows == 0) {
      out.push_back({"rings", lidar.name, Severity::kOk, rows_without_model(t)});
    } else if (t.with_ring == 0) {
      out.push_back({"rings", lidar.name, Severity::kOk, "no ring field: rows come from the elevation against the model's angles"});
    } else if (t.max_ring + 1 != rows) {
      out.push_back({"rings", lidar.name, t.max_ring + 1 > rows ? Severity::kWarning : Severity::kOk,
                     "ring values reach " + std::to_string(t.max_ring) + " for a model of " + std::to_string(rows) + " rows" +
                         (t.max_ring + 1 > rows ? ": points beyond the model's rows are dropped; check the model in dataset.yaml"
                                                : " (its top rows saw nothing)")});
    } else {
      out.push_back({"rings", lidar.name, Severity::kOk, std::to_string(t.max_ring + 1) + " rings"});
    }
  }
}

void check_extrinsics(const io::FrameSource& source, const DoctorConfig& config, std::vector<Finding>& out) {
  const std::optional<std::size_t> base = source.reference_index();
  for (std::size_t j = 0; j < source.lidars().size(); ++j) {
    const io::SourceLidar& lidar = source.lidars()[j];
    if (!lidar.initial_extrinsic) {
      out.push_back({"extrinsics", lidar.name, Severity::kWarning,
                     "no extrinsic given: `slam --calibrate fixed|refine` need one; run `mlidar calibrate auto` first (or slam "
                     "--calibrate online)"});
      continue;
    }
    const double distance = lidar.initial_extrinsic->translation().norm();
    if (base && j == *base && (distance > 1e-6 || so3_log(lidar.initial_extrinsic->rotation()).norm() > 1e-6)) {
      out.push_back({"extrinsics", lidar.name, Severity::kOk,
                     "the base LiDAR sits off the base frame (" + number(distance) + " m): fine, the frame is the dataset's"});
    } else if (distance > config.max_translation_m) {
      out.push_back({"extrinsics", lidar.name, Severity::kWarning,
                     number(distance) + " m from the base: implausible on one vehicle; check the units (mm?) and the direction "
                                        "(p_base = R p_lidar + t)"});
    } else {
      out.push_back({"extrinsics", lidar.name, Severity::kOk, number(distance) + " m from the base"});
    }
  }
}

/// The share of `points` (in the base frame) within `radius` of the base's points.
double overlap_share(const KdTree3f& base_tree, const std::vector<Eigen::Vector3f>& points, float radius) {
  if (points.empty()) return 0.0;
  std::size_t near = 0;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / 5000);  // a sample is enough
  std::size_t tried = 0;
  for (std::size_t i = 0; i < points.size(); i += stride, ++tried) {
    const std::vector<Neighbor> n = base_tree.knn(points[i], 1);
    if (!n.empty() && n.front().distance_sq <= radius * radius) ++near;
  }
  return static_cast<double>(near) / static_cast<double>(tried);
}

std::vector<Eigen::Vector3f> in_base(const Scan& scan, const SE3& T_base_lidar) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(scan.size());
  for (const Eigen::Vector3f& p : scan.points)
    if (p.allFinite()) out.push_back((T_base_lidar * Vec3(p.cast<double>())).cast<float>());
  return out;
}

void check_overlap(const io::FrameSource& source, std::vector<LidarTally>& tallies, const DoctorConfig& config, std::vector<Finding>& out) {
  const std::optional<std::size_t> base = source.reference_index();
  if (!base || !tallies[*base].first || !source.lidars()[*base].initial_extrinsic) return;
  const SE3& T_base_reference = *source.lidars()[*base].initial_extrinsic;
  const KdTree3f tree(in_base(*tallies[*base].first, T_base_reference));
  for (std::size_t j = 0; j < tallies.size(); ++j) {
    const io::SourceLidar& lidar = source.lidars()[j];
    if (j == *base || !tallies[j].first || !lidar.initial_extrinsic) continue;
    const double share =
        overlap_share(tree, in_base(*tallies[j].first, *lidar.initial_extrinsic), static_cast<float>(config.overlap_radius_m));
    const std::string seen = number(100 * share, "%.0f") + " % of its first scan lies within " + number(config.overlap_radius_m) +
                             " m of the base's at the given extrinsic";
    if (share < config.min_overlap)
      out.push_back({"overlap", lidar.name, Severity::kWarning,
                     seen + ": the appearance refinement needs overlap (drive so both see the same surfaces, or check the "
                            "extrinsic); hand-eye from motion still works"});
    else
      out.push_back({"overlap", lidar.name, Severity::kOk, seen});
  }
}

void check_motion(const io::FrameSource& source, const std::optional<BaseMotion>& motion, const DoctorConfig& config,
                  std::vector<Finding>& out) {
  const std::optional<std::size_t> base = source.reference_index();
  if (!motion || !base) return;
  const std::string& name = source.lidars()[*base].name;
  const MotionSummary m = motion->summary(source.period(), config.motion);
  const std::string gap = number(config.motion.pair_seconds) + " s";
  if (m.registered * 2 < m.frames) {
    out.push_back({"motion", name, Severity::kWarning,
                   "the base's own odometry registered " + std::to_string(m.registered) + " of " + std::to_string(m.frames) +
                       " frames, so its motion is unknown here: check its scans and model (see above), or give extrinsics and run "
                       "--calibrate refine or fixed"});
    return;
  }
  if (m.turning_pairs < config.motion.min_turning_pairs) {
    out.push_back({"motion", name, Severity::kWarning,
                   "the base turns at most " + number(m.largest_turn_deg, "%.2g") + " deg in " + gap + " (" +
                       std::to_string(m.turning_pairs) + " of " + std::to_string(m.pairs) + " frame pairs turn " +
                       number(config.motion.turn_deg) +
                       " deg or more): hand-eye calibration (slam --calibrate online, calibrate "
                       "auto) needs turns, about two axes for all six degrees; record with turns, or give extrinsics and run "
                       "--calibrate refine or fixed"});
    return;
  }
  const std::string seen = std::to_string(m.turning_pairs) + " of " + std::to_string(m.pairs) + " frame pairs " + gap +
                           " apart turn (up to " + number(m.largest_turn_deg, "%.2g") + " deg), second axis " +
                           number(100 * m.axis_spread, "%.0f") + " % of the first";
  if (m.axis_spread < config.motion.min_axis_spread)
    out.push_back({"motion", name, Severity::kWarning,
                   seen + ": every turn is about the base's " + base_axis_words(m.main_axis) +
                       " (planar motion), so hand-eye cannot see the translation along it; slam then takes it from the "
                       "ground planes. Tilt or rock the rig for a full hand-eye, or give extrinsics (--calibrate refine)"});
  else
    out.push_back({"motion", name, Severity::kOk, seen + ": enough for hand-eye"});
}

}  // namespace

const char* to_string(Severity severity) {
  switch (severity) {
    case Severity::kOk:
      return "ok";
    case Severity::kWarning:
      return "warning";
    case Severity::kFailure:
      return "failure";
  }
  return "?";
}

std::vector<Finding> examine(const io::FrameSource& source, const DoctorConfig& config) {
  std::vector<Finding> out;
  check_stamps(source, config, out);
  std::optional<BaseMotion> motion;
  if (const std::optional<std::size_t> base = source.reference_index(); base && config.check_motion) {
    try {
      motion.emplace(source.lidars()[*base]);
    } catch (const std::exception&) {  // a model the odometry cannot take: the rings check names it
    }
  }
  std::vector<LidarTally> tallies = read_all(source, config, motion, out);
  check_scans(source, tallies, config, out);
  check_times_and_rings(source, tallies, config, out);
  check_extrinsics(source, config, out);
  check_overlap(source, tallies, config, out);
  check_motion(source, motion, config, out);
  return out;
}

bool has_failure(const std::vector<Finding>& findings) {
  return std::any_of(findings.begin(), findings.end(), [](const Finding& f) { return f.severity == Severity::kFailure; });
}

std::vector<Finding> examine_input(const std::filesystem::path& input, io::BagArguments bag, const DoctorConfig& config) {
  const bool folder = std::filesystem::is_directory(input);
  bag.bag = folder ? std::string{} : input.string();
  try {
    const io::FrameSource source = open_frames(folder ? input : std::filesystem::path{}, bag.bag, io::bag_source_options(bag));
    return examine(source, config);
  } catch (const InputError& error) {  // what every job would stop at before its first frame
    return {{"open", "", Severity::kFailure, error.what()}};
  }
}

nlohmann::json doctor_json(const std::string& input, const std::vector<Finding>& findings) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& f : findings)
    list.push_back({{"check", f.check}, {"lidar", f.lidar}, {"severity", to_string(f.severity)}, {"message", f.message}});
  return {{"input", input}, {"failed", has_failure(findings)}, {"findings", list}};
}

}  // namespace mlidar::pipelines
