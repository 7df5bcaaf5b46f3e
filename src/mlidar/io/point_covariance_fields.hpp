#pragma once
// Per-point covariances in a cloud (map.ply of an uncertainty-aware run): the
// float fields cov_xx cov_xy cov_xz cov_yy cov_yz cov_zz (m^2, the cloud's
// frame) and cov_trace = cov_xx + cov_yy + cov_zz.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

/// xx, xy, xz, yy, yz, zz.
using UpperCovariance = std::array<float, 6>;

/// The symmetric 3x3 matrix an upper triangle stands for, and the upper triangle of a (symmetric) matrix.
Eigen::Matrix3d to_matrix(const UpperCovariance& c);
UpperCovariance to_upper(const Eigen::Matrix3d& m);
/// cov_xx + cov_yy + cov_zz, summed in double (the cov_trace field holds the float sum).
inline double covariance_trace(const UpperCovariance& c) { return static_cast<double>(c[0]) + c[3] + c[5]; }

inline constexpr const char* kCovarianceFieldNames[] = {"cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"};

/// Adds the six fields and cov_trace (one covariance per point of `table`; std::invalid_argument otherwise).
void add_point_covariances(PointTable& table, const std::vector<UpperCovariance>& covariances);

/// The covariances of a cloud, nullopt when it has none of the fields. InputError naming `source`, the field and
/// the point for: some fields but not all six, a non-finite value, a negative variance, a covariance that is
/// not positive semi-definite (beyond rounding), or a cov_trace that disagrees with the diagonal.
std::optional<std::vector<UpperCovariance>> read_point_covariances(const PointTable& table, const std::string& source);

}  // namespace mlidar::io
