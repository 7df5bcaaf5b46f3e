#pragma once
// Data of the M-LOAM sliding-window back end (thesis sec 4.7, eq 4.19-4.22).
//
// Variables (eq 4.19): poses T_world_base_i, i = 0..N (oldest first), and
// extrinsics T_base_lidar_j, j = 0..L-1 (j = 0 is the base LiDAR, always held
// fixed). Units: metres, radians. Every variable is updated by a left
// perturbation X <- Exp(delta) X with delta = [t, r] (mlidar's tangent order),
// so one variable is one 6-column block of the tangent vector.
//
// Residuals: a feature point x in LiDAR j's frame at frame i maps to the world
// point q = T_world_base_i * T_base_lidar_j * x and is matched to the local
// map's plane (eq 4.7) or line (eq 4.8), both given in the world frame and held
// constant while optimizing. Online calibration (eq 4.21) leaves the auxiliary
// extrinsics variable; pure odometry (eq 4.22) holds them fixed.
//
// The map is either fixed in the world (it then fixes the gauge) or, as in the
// thesis, attached to a window pose, the pivot p (MapAnchor): a feature of
// frame i is then matched in the pivot's frame, r(T_world_base_p^-1
// T_world_base_i T_base_lidar x), so each term couples the pivot and frame i.
// The planes and lines are stored in world coordinates at the pivot's
// reference estimate T0_p; at an estimate T_p they move with D = T_p T0_p^-1
// (equivalently the point goes to D^-1 q), and the pivot's gradient is minus
// the frame pose's (window_linearize.hpp). Holding poses fixed (the thesis holds
// x_1..x_p, the frames that built the map) is the caller's choice.
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"
#include "mlidar/slam/residuals.hpp"

namespace mlidar::slam {

/// One 6-dof block of the window's state.
struct VariableId {
  enum class Kind { kPose, kExtrinsic };
  Kind kind = Kind::kPose;
  int index = 0;  ///< pose i (frame in the window) or extrinsic j (LiDAR)
  friend bool operator==(const VariableId&, const VariableId&) = default;
};

/// The window's estimates and which of them are held fixed.
struct WindowState {
  std::vector<SE3> T_world_base;      ///< pose of the base frame at frame i, i = 0..N (oldest first)
  std::vector<SE3> T_base_lidar;      ///< LiDAR j in the base frame, j = 0..L-1
  std::vector<bool> pose_fixed;       ///< same size as T_world_base
  std::vector<bool> extrinsic_fixed;  ///< same size as T_base_lidar; [0] must be true

  /// poses.size() poses of which the first `fixed_poses` are held fixed; the
  /// base extrinsic (j = 0) fixed, the others per `calibrate`.
  static WindowState make(std::vector<SE3> poses, std::vector<SE3> extrinsics, int fixed_poses, bool calibrate);
  const SE3& value(VariableId id) const;
  SE3& value(VariableId id);
  bool fixed(VariableId id) const;
};

/// Eq 4.21 (kCalibrate: auxiliary extrinsics are variables) or eq 4.22 (kFixed).
enum class ExtrinsicMode { kCalibrate, kFixed };
/// Sets extrinsic_fixed: the base LiDAR always fixed, the others per mode.
void set_extrinsic_mode(WindowState& state, ExtrinsicMode mode);

/// Feature of LiDAR `lidar` at window frame `frame` on a map plane (eq 4.7).
struct PlaneCorrespondence {
  int frame = 0;
  int lidar = 0;
  Vec3 point_lidar = Vec3::Zero();  ///< metres, LiDAR frame
  PlaneCoefficients plane_world;    ///< unit normal, offset: n^T q + d = 0 in the world
};

/// Feature on a map line (eq 4.8) through line_point_world along line_direction_world.
struct EdgeCorrespondence {
  int frame = 0;
  int lidar = 0;
  Vec3 point_lidar = Vec3::Zero();
  Vec3 line_point_world = Vec3::Zero();
  Vec3 line_direction_world = Vec3::UnitX();  ///< unit
};

/// Linear prior left by marginalization (eq 4.43-4.44): cost 1/2 |r* + J* dx|^2
/// with dx the stacked tangent differences dx_k = Log(X_k X0_k^-1) of its
/// variables from their linearization points X0_k. J* is never re-linearized
/// (first-estimate Jacobians); J*^T J* = Lambda*_rr, J*^T r* = g*_r (eq 4.41).
struct LinearPrior {
  std::vector<VariableId> variables;      ///< 6-column blocks of J*, in order
  std::vector<SE3> linearization_points;  ///< X0_k, one per variable
  Eigen::MatrixXd jacobian;               ///< J*: rank x 6 * variables.size()
  Eigen::VectorXd residual;               ///< r*: rank
};

/// Where the map's planes and lines live (see the top of this file).
struct MapAnchor {
  int frame = -1;              ///< the window pose the map is attached to (the pivot); -1: fixed in the world
  SE3 T_world_base_reference;  ///< that pose's estimate when the planes and lines were found (world coordinates)
};

/// The window's cost terms (eq 4.20): map residuals f_M and the prior r_pri.
struct WindowProblem {
  std::vector<PlaneCorrespondence> planes;
  std::vector<EdgeCorrespondence> edges;
  MapAnchor anchor;   ///< of every plane and edge above
  LinearPrior prior;  ///< empty (no variables) when there is none
};

/// D = T_p T0_p^-1: how far the anchored map moved from where it was found (identity when not anchored).
SE3 map_motion(const MapAnchor& anchor, const WindowState& state);

/// Column offsets of the variable (non-fixed) blocks in the tangent vector:
/// poses first (i ascending), then extrinsics; -1 for a fixed block.
struct VariableLayout {
  std::vector<int> pose_offset;
  std::vector<int> extrinsic_offset;
  int size = 0;

  explicit VariableLayout(const WindowState& state);
  int offset(VariableId id) const;
};

/// Throws std::invalid_argument when sizes or indices disagree (a programmer error).
void check_problem(const WindowProblem& problem, const WindowState& state);

}  // namespace mlidar::slam
