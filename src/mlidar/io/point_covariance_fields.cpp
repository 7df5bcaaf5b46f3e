#include "mlidar/io/point_covariance_fields.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mlidar/core/error.hpp"

namespace mlidar::io {
namespace {

std::string at_point(std::size_t i) { return " at point " + std::to_string(i); }

/// Why a covariance read from a file is unusable, or empty.
std::string problem_of(const UpperCovariance& c) {
  for (const float v : c)
    if (!std::isfinite(v)) return "holds a non-finite value";
  if (c[0] < 0.0F || c[3] < 0.0F || c[5] < 0.0F) return "has a negative variance";
  const Eigen::Matrix3d m = to_matrix(c);
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m, Eigen::EigenvaluesOnly).eigenvalues()(0);
  const double scale = std::max(1e-12, m.diagonal().maxCoeff());
  if (smallest < -1e-5 * scale) return "is not positive semi-definite (smallest eigenvalue " + std::to_string(smallest) + " m^2)";
  return {};
}

}  // namespace

Eigen::Matrix3d to_matrix(const UpperCovariance& c) {
  Eigen::Matrix3d m;
  m << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
  return m;
}

UpperCovariance to_upper(const Eigen::Matrix3d& m) {
  return {static_cast<float>(m(0, 0)), static_cast<float>(m(0, 1)), static_cast<float>(m(0, 2)),
          static_cast<float>(m(1, 1)), static_cast<float>(m(1, 2)), static_cast<float>(m(2, 2))};
}

void add_point_covariances(PointTable& table, const std::vector<UpperCovariance>& covariances) {
  if (covariances.size() != table.num_points) throw std::invalid_argument("add_point_covariances: one covariance per point");
  std::vector<float> values(covariances.size());
  for (std::size_t k = 0; k < 6; ++k) {
    for (std::size_t i = 0; i < covariances.size(); ++i) values[i] = covariances[i][k];
    add_f32_field(table, kCovarianceFieldNames[k], values);
  }
  for (std::size_t i = 0; i < covariances.size(); ++i)
    values[i] = covariances[i][0] + covariances[i][3] + covariances[i][5];  // in float, as read back
  add_f32_field(table, "cov_trace", values);
}

std::optional<std::vector<UpperCovariance>> read_point_covariances(const PointTable& table, const std::string& source) {
  std::array<const FieldColumn*, 6> columns{};
  std::size_t present = 0;
  for (std::size_t k = 0; k < 6; ++k) present += (columns[k] = table.find(kCovarianceFieldNames[k])) != nullptr ? 1 : 0;
  if (present == 0) return std::nullopt;
  for (std::size_t k = 0; k < 6; ++k)
    if (columns[k] == nullptr)
      throw InputError(source, kCovarianceFieldNames[k], "missing while other cov_ fields are present: give all six or none");
  std::vector<UpperCovariance> out(table.num_points);
  const FieldColumn* trace = table.find("cov_trace");
  for (std::size_t i = 0; i < table.num_points; ++i) {
    for (std::size_t k = 0; k < 6; ++k) out[i][k] = static_cast<float>(columns[k]->value(i));
    const std::string problem = problem_of(out[i]);
    if (!problem.empty()) throw InputError(source, "cov_xx..cov_zz", "the covariance" + at_point(i) + " " + problem);
    if (trace != nullptr) {
      const double sum = covariance_trace(out[i]);
      const double given = trace->value(i);
      if (!(std::abs(given - sum) <= 1e-4 * std::max(1e-6, std::abs(sum))))
        throw InputError(source, "cov_trace",
                         "is " + std::to_string(given) + at_point(i) + " but cov_xx + cov_yy + cov_zz = " + std::to_string(sum) +
                             ": write the sum of the diagonal");
    }
  }
  return out;
}

}  // namespace mlidar::io
