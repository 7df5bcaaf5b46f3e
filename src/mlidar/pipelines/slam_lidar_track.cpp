#include "mlidar/pipelines/slam_lidar_track.hpp"

#include <algorithm>
#include <utility>

#include "mlidar/calib/ground_up.hpp"

namespace mlidar::pipelines {
namespace {

slam::LidarSetup with_extrinsic(slam::LidarSetup setup, const SE3& T_base_lidar) {
  setup.T_base_lidar = T_base_lidar;
  return setup;
}

/// Xi_calib's autocorrelation floor: a window spans N + 1 frames, consecutive ones share N.
calib::ConvergenceConfig with_window_overlap(calib::ConvergenceConfig config, int window_size) {
  config.min_autocorrelation_time = window_size + 1.0;
  return config;
}

LidarRole initial_role(bool is_base, ExtrinsicSource source) {
  if (is_base || source == ExtrinsicSource::fixed) return LidarRole::trusted;
  return source == ExtrinsicSource::refine ? LidarRole::calibrating : LidarRole::initializing;
}

/// The frames where the LiDAR's role went from `from` to `to` (its role after each frame; `initial` before the first).
std::vector<std::size_t> transitions(std::span<const SlamFrame> frames, std::size_t index, LidarRole initial, LidarRole from,
                                     LidarRole to) {
  std::vector<std::size_t> found;
  LidarRole before = initial;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const LidarRole after = frames[k].lidars[index].role;
    if (before == from && after == to) found.push_back(k);
    before = after;
  }
  return found;
}

std::optional<std::size_t> last_of(const std::vector<std::size_t>& frames) {
  return frames.empty() ? std::nullopt : std::optional(frames.back());
}

}  // namespace

std::string_view to_string(LidarRole role) {
  switch (role) {
    case LidarRole::initializing:
      return "initializing";
    case LidarRole::calibrating:
      return "calibrating";
    case LidarRole::trusted:
      return "trusted";
  }
  return "unknown";
}

std::string_view to_string(ExtrinsicSource source) {
  switch (source) {
    case ExtrinsicSource::online:
      return "online";
    case ExtrinsicSource::refine:
      return "refine";
    case ExtrinsicSource::fixed:
      return "fixed";
  }
  return "unknown";
}

std::string_view to_string(TranslationStart start) {
  switch (start) {
    case TranslationStart::none:
      return "";
    case TranslationStart::hand_eye:
      return "hand_eye";
    case TranslationStart::zero:
      return "zero";
    case TranslationStart::appearance:
      return "appearance";
  }
  return "";
}

std::string_view to_string(AxisTranslationSource source) {
  switch (source) {
    case AxisTranslationSource::none:
      return "";
    case AxisTranslationSource::ground_planes:
      return "ground planes";
    case AxisTranslationSource::set_to_zero:
      return "set to 0";
  }
  return "";
}

LidarTrack::LidarTrack(slam::LidarSetup setup, bool is_base, ExtrinsicSource source, const SlamConfig& config)
    : config_(&config),
      setup_(std::move(setup)),
      T_g_lidar_(setup_.T_base_lidar.rotation(), Vec3::Zero()),
      initial_role_(initial_role(is_base, source)),
      monitor_({SE3::identity()}, with_window_overlap(config.convergence, config.window.size)),
      state_(initial_state()) {
  // The base defines the base frame; online, the given extrinsic serves as the own odometry's up only: the estimate
  // never starts from it.
  if (is_base || source == ExtrinsicSource::online) setup_.T_base_lidar = SE3::identity();
  given_T_base_lidar_ = setup_.T_base_lidar;
}

std::variant<LidarTrack::Initializing, LidarTrack::Calibrating, LidarTrack::Trusted> LidarTrack::initial_state() {
  switch (initial_role_) {
    case LidarRole::initializing:
      return start_initializing(true);
    case LidarRole::calibrating:
      return Calibrating{};
    case LidarRole::trusted:
      break;
  }
  return Trusted{};
}

LidarRole LidarTrack::role() const {
  if (std::holds_alternative<Initializing>(state_)) return LidarRole::initializing;
  return std::holds_alternative<Calibrating>(state_) ? LidarRole::calibrating : LidarRole::trusted;
}

std::unique_ptr<slam::Odometry> LidarTrack::own_odometry() const {
  auto own = std::make_unique<slam::Odometry>(config_->odometry, std::vector{with_extrinsic(setup_, T_g_lidar_)});
  // Its poses are the hand-eye's input: every feature, as the trusted odometry's while calibrating.
  own->set_selection_paused(!config_->odometry.registration.selection.while_calibrating);
  return own;
}

LidarTrack::Initializing LidarTrack::start_initializing(bool own_odometry_now) {
  Initializing state{nullptr, calib::OnlineHandEye(config_->initialization), {}, {}, 0, false, std::nullopt, 0};
  if (own_odometry_now) state.own = own_odometry();
  return state;
}

TrackTransition LidarTrack::step(const TrackFrame& frame, const std::optional<Scan>& scan, SlamLidarFrame& out) {
  if (auto* initializing = std::get_if<Initializing>(&state_)) {
    if (!initializing->first_frame) {
      initializing->first_frame = frame.index;
      initializing->next_appearance = frame.index + config_->start.appearance_after_frames;
    }
    if (!scan) {
      initializing->recent.clear();  // no motion pair across the gap
      initializing->after_gap = true;
      return TrackTransition::none;
    }
    if (std::exchange(initializing->after_gap, false) && initializing->own) {
      // Its own odometry starts again after a gap: across 10 s without scans its map and motion prior no longer
      // held, every later frame came out lost and the hand-eye never got another pair.
      initializing->own = own_odometry();
    }
    if (!initializing->own) {
      // After a shock the old extrinsic's up is off by up to the shock's tilt (~14 deg in Table 4.6), beyond the
      // ground segmentation's 10 deg: its own odometry then drifted and the hand-eye kept 14 of ~110 pairs in 116
      // frames (rhd campus, seed 1). The ground plane of the scan near that up corrects it.
      const Vec3 prior_up = T_g_lidar_.rotation().conjugate() * Vec3::UnitZ();
      if (const std::optional<Vec3> up = calib::ground_up(scan->points, prior_up))
        T_g_lidar_ = SE3(calib::align_up(T_g_lidar_.rotation(), *up), Vec3::Zero());
      initializing->own = own_odometry();
    }
    return initialize(*initializing, frame, *scan);
  }
  if (auto* calibrating = std::get_if<Calibrating>(&state_)) {
    if (!scan) {
      calibrating->pending.reset();  // the next scan is deskewed on its own
      return TrackTransition::none;
    }
    if (frame.odometry->flagged()) return TrackTransition::none;
    return calibrate(*calibrating, frame, *scan, out);
  }
  return TrackTransition::none;
}

void LidarTrack::restart_after_shock() {
  T_g_lidar_ = SE3(setup_.T_base_lidar.rotation(), Vec3::Zero());
  monitor_.restart(0);
  state_ = start_initializing(false);  // restarted at its next scan, with up from that scan's ground
}

bool LidarTrack::extrinsic_given() const {
  const auto* trusted = std::get_if<Trusted>(&state_);
  return trusted != nullptr && !trusted->covariance;
}

void LidarTrack::given_disagrees(ExtrinsicDisagreement disagreement, bool recalibrate) {
  disagreement_ = disagreement;
  disagreement_->recalibrated = recalibrate;
  if (!recalibrate) return;
  monitor_.restart(0);
  state_ = Calibrating{};
}

SlamLidarReport LidarTrack::report(std::span<const SlamFrame> frames, std::size_t index) const {
  SlamLidarReport r;
  r.name = setup_.name;
  r.role = role();
  r.T_base_lidar = setup_.T_base_lidar;
  if (const auto* trusted = std::get_if<Trusted>(&state_)) {
    r.covariance = trusted->covariance;
    r.covariance_parts = trusted->parts;
  }
  const calib::LidarCalibrationState& monitor = monitor_.lidar(0);
  r.accepted = monitor.accepted.size();
  r.outliers = monitor.outliers;
  r.weak = monitor.weak;
  r.initialization = start_.status;
  r.translation_start = start_.translation_start;
  r.unobservable_from_motion = start_.unobservable_from_motion;
  r.axis_translation_source = start_.axis_translation_source;
  r.appearance_attempts = start_.appearance;
  const auto converged = transitions(frames, index, initial_role_, LidarRole::calibrating, LidarRole::trusted);
  r.converged_frame = last_of(converged);
  if (!converged.empty()) r.first_converged_frame = converged.front();
  r.initialized_frame = last_of(transitions(frames, index, initial_role_, LidarRole::initializing, LidarRole::calibrating));
  r.restarts = transitions(frames, index, initial_role_, LidarRole::trusted, LidarRole::initializing).size();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const SlamLidarFrame& l = frames[k].lidars[index];
    r.missing_frames += l.scan_missing ? 1 : 0;
    if (l.shock) r.shock_frames.push_back(k);
    if (l.reinitialized) r.reinitialization_frames.push_back(k);
  }
  r.disagreement = disagreement_;
  r.given_T_base_lidar = given_T_base_lidar_;
  return r;
}

}  // namespace mlidar::pipelines
