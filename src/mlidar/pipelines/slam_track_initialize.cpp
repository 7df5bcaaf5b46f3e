// LidarTrack's Initializing state: the LiDAR's own odometry paired with the
// trusted poses (eq 4.13) and screened by eq 3.4 into the online hand-eye (eq
// 4.15-4.18), then the start of the calibration window; under planar motion
// the height along the axis from the ground planes (eq 3.8-3.12, thesis
// 3.4.3.1); after StartParams::appearance_after_frames without a start, the
// appearance start (slam_appearance_start.hpp).
#include <cstdio>
#include <string>
#include <vector>

#include "mlidar/calib/ground_height.hpp"
#include "mlidar/calib/hand_eye.hpp"
#include "mlidar/pipelines/slam_lidar_track.hpp"

namespace mlidar::pipelines {
namespace {

std::string describe_axis(const Vec3& axis) {
  char text[64];
  std::snprintf(text, sizeof text, "(%.2f, %.2f, %.2f) of the base", axis.x(), axis.y(), axis.z());
  return text;
}

}  // namespace

TrackTransition LidarTrack::initialize(Initializing& state, const TrackFrame& frame, const Scan& scan) {
  if (frame.base_scan != nullptr) {
    state.ground.emplace_back(*frame.base_scan, scan);
    if (state.ground.size() > kGroundFrames) state.ground.pop_front();
  }
  const slam::FrameResult own = state.own->process(Frame{frame.stamp, {scan}});
  if (own.flagged() || frame.odometry->flagged()) {
    state.recent.clear();  // no motion pair across a frame that did not register
    return TrackTransition::none;
  }
  add_motion_pair(state, {own.T_world_base * T_g_lidar_, frame.odometry->T_world_base});
  const calib::OnlineHandEyeStatus& status = state.hand_eye.status();
  start_.status = status;
  const std::size_t zero_after = config_->start.zero_translation_after_pairs;
  const bool zero_translation = zero_after > 0 && state.rotation_only_pairs >= zero_after;
  if (status.state != calib::OnlineHandEyeState::ready && !zero_translation) return TrackTransition::none;
  // Without a translation from motion, the window (gates 1.0 / 0.3 m) starts from t = 0.
  setup_.T_base_lidar = zero_translation ? SE3(status.T_base_lidar.rotation(), Vec3::Zero()) : status.T_base_lidar;
  start_.translation_start = zero_translation ? TranslationStart::zero : TranslationStart::hand_eye;
  start_.unobservable_from_motion.clear();
  start_.axis_translation_source = AxisTranslationSource::none;
  if (status.state == calib::OnlineHandEyeState::ready && status.planar_motion) set_planar_height(state);
  state_ = Calibrating{};  // `state` is gone from here on
  return TrackTransition::started_calibration;
}

bool LidarTrack::appearance_due(std::size_t frame) const {
  const auto* state = std::get_if<Initializing>(&state_);
  return state != nullptr && config_->start.appearance_after_frames > 0 && state->first_frame && frame >= state->next_appearance;
}

TrackTransition LidarTrack::start_by_appearance(const AppearanceHistory& history, const slam::LidarSetup& base, std::size_t j,
                                                std::size_t frame) {
  auto& state = std::get<Initializing>(state_);
  state.next_appearance = frame + config_->start.appearance_after_frames;
  const calib::OnlineHandEyeStatus& status = state.hand_eye.status();
  // Hand-eye's estimate is the refinement's first start (its rotation once ready; identity before any pair).
  AppearanceAttempt attempt = appearance_start(history, *state.first_frame, base, setup_, j, status.T_base_lidar, config_->appearance);
  attempt.frame = frame;
  start_.appearance.push_back(attempt);
  if (!attempt.ok) return TrackTransition::none;
  setup_.T_base_lidar = *attempt.T_base_lidar;
  start_.status = status;
  start_.translation_start = TranslationStart::appearance;
  start_.axis_translation_source = AxisTranslationSource::none;
  start_.unobservable_from_motion.clear();
  const auto& sv = status.singular_values;
  if (status.pairs_stored >= config_->initialization.planar_min_pairs && sv[2] < 0.1 * sv[1]) {  // one common rotation axis
    start_.unobservable_from_motion = {"translation along the rotation axis and rotation about it (the motion turned about one axis; "
                                       "started from the appearance instead)"};
  } else if (status.state == calib::OnlineHandEyeState::rotation_ready) {
    start_.unobservable_from_motion = {"translation (the hand-eye's rotation was ready, its translation not; started from the "
                                       "appearance instead)"};
  } else {
    char text[200];
    std::snprintf(text, sizeof text,
                  "rotation and translation (%zu motion pairs of its own odometry, rotation test %.3g below sigma_R %.3g; started from the "
                  "appearance instead)",
                  status.pairs_stored, sv[2], config_->initialization.rotation_threshold);
    start_.unobservable_from_motion = {text};
  }
  state_ = Calibrating{};  // `state` is gone from here on
  return TrackTransition::started_calibration;
}

void LidarTrack::add_motion_pair(Initializing& state, const PosePair& pose) {
  state.recent.push_back(pose);
  if (state.recent.size() <= kPairStride) return;
  // Eq 4.13 over kPairStride frames: A = T_{b_{k-s} b_k}, B = T_{l_{k-s} l_k}.
  const PosePair& from = state.recent.front();
  const calib::MotionPair pair{from.T_world_base.inverse() * pose.T_world_base, from.T_world_lidar.inverse() * pose.T_world_lidar};
  state.recent.pop_front();
  // Eq 3.4: both motions of a rigid rig share the screw angle and pitch. A
  // pair whose angles differ is kept out; one whose pitches differ gives its
  // rotation only (eq 4.15, not 4.18): on campus seeds 2 and 5 the LiDAR's
  // own translations were off by up to metres (degenerate scenes) while its
  // rotations were within 0.01 rad, so the screw test kept 9-14 of ~140 pairs.
  const calib::HandEyeConfig screw;
  const calib::ScrewResidual residual = calib::screw_residual(pair, screw);
  if (residual.angle_rad > screw.screw_angle_tolerance_rad) return;
  state.hand_eye.add(pair, residual.inlier);
  const bool rotation_only = state.hand_eye.status().state == calib::OnlineHandEyeState::rotation_ready;
  state.rotation_only_pairs = rotation_only ? state.rotation_only_pairs + 1 : 0;
}

void LidarTrack::set_planar_height(const Initializing& state) {
  // Planar motion: t along the rotation axis is not observable from motion;
  // the ground planes of both LiDARs fix it (thesis 3.4.3.1), else it stays 0.
  const calib::OnlineHandEyeStatus& s = state.hand_eye.status();
  start_.unobservable_from_motion = {"translation along the rotation axis " + describe_axis(s.unobservable_axis_base)};
  if (s.planar_rotation) start_.unobservable_from_motion.push_back("rotation about that axis (solved from the translations, eq 3.10-3.12)");
  std::vector<Scan> base_scans, lidar_scans;
  for (const auto& [base, lidar] : state.ground) {
    base_scans.push_back(base);
    lidar_scans.push_back(lidar);
  }
  const calib::GroundHeightResult height =
      calib::height_from_ground(base_scans, lidar_scans, setup_.T_base_lidar, s.unobservable_axis_base);
  start_.axis_translation_source = height.frames_used > 0 ? AxisTranslationSource::ground_planes : AxisTranslationSource::set_to_zero;
  if (height.frames_used > 0) setup_.T_base_lidar = height.T_a_b;
}

}  // namespace mlidar::pipelines
