#pragma once
// Good-feature selection for scan-to-map registration (thesis Ch. 5).
// Problem eq 5.4: choose S with |S| <= M maximising f(S) = log det Lambda(S),
// Lambda(S) = delta I + sum_{i in S} Lambda_i, Lambda_i = J_i^T Sigma_i^-1 J_i
// (eq 5.3: the robust weight rho' over the point's variance; here Sigma = I m^2,
// the registration's own scaling, so Lambda(F) is its Gauss-Newton H at the start).
// A plane feature is one scalar row (rank 1), an edge two (rank 2).
// delta I (delta = kPriorInformation) makes f finite for |S| < 6; f - 6 log delta
// is then normalised, monotone and submodular, which is what eq 5.5 needs.
//
// Stochastic greedy (Algorithm 2, Mirzasoleiman et al. 2015): each round draws
// ceil(N / M * log(1 / epsilon)) features from those not yet chosen and adds
// the one whose gain log det(Lambda(S) + Lambda_i) - log det Lambda(S) is
// largest. The gain comes from the matrix determinant lemma with the Cholesky
// factor L of Lambda(S), computed once per round:
//   log det(I_k + V^T V),  V = L^-1 U_i,  Lambda_i = U_i U_i^T
// (one 6 x k triangular solve per candidate, no decomposition per candidate).
// A feature's correspondence is searched when it is first drawn (lines 4-10):
// one without is dropped from F, so only the drawn features cost a search
// (about N (1 - epsilon) of them for greedy, M / match rate for random).
//
// M adapts to degeneracy (sec 5.4.4), evaluated every degeneracy_interval_s
// over all features that found a correspondence (a search of every feature):
// a well-conditioned scene keeps `ratio` of them, a degenerate one
// `degenerate_ratio` (thesis: 0.2 and 0.8). The thesis's factor is
// lambda = log det Lambda(F) with a fixed threshold; on our data it does not
// separate the corridor from well-conditioned scenes (per frame: corridors
// 37.7-45.2, rhd room 44.3-48.5; it also grows by 4.2 for twice the
// features), so the scene counts as degenerate on the scale-free translation
// observability of Lambda(F) (Zhang et al. 2016, as the registration judges
// degeneracy): corridors 0.03-0.07, campus and room mostly 0.1-0.9
// (docs/benchmarks.md "Feature selection"). lambda is still reported.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"

namespace mlidar::slam {

enum class SelectionMethod : std::uint8_t {
  kNone,    ///< every feature (the registration as without selection)
  kRandom,  ///< M features drawn uniformly (the thesis's "rnd")
  kGreedy,  ///< stochastic greedy on log det (Algorithm 2)
};
const char* selection_method_name(SelectionMethod method);  ///< "none", "random", "greedy"

struct SelectionConfig {
  SelectionMethod method = SelectionMethod::kNone;
  double ratio = 0.2;             ///< M / N in a well-conditioned scene (or always, without `adaptive`)
  bool adaptive = true;           ///< M from the scene's degeneracy (sec 5.4.4)
  double degenerate_ratio = 0.8;  ///< M / N in a degenerate scene
  /// Degenerate below this translation observability of Lambda(F) (the
  /// registration's own threshold; measured per frame: corridors 0.032-0.071,
  /// rhd room 0.59-0.88, rhd campus 0.11-0.33, rv campus 0.046-0.31).
  double degeneracy_threshold = 0.1;
  double degeneracy_interval_s = 1.0;  ///< lambda is evaluated again after this long (thesis: 1-2 s)
  /// Decay factor of the random subset size (eq 5.5's epsilon). Each drawn
  /// feature costs a map search, and greedy draws N log(1 / epsilon) in all:
  /// 0.1 searches 90 % of the features (no time saved on rv), 0.8 about 40 %
  /// at the same ATE (docs/benchmarks.md); eq 5.5's bound needs epsilon < 1 - 1/e.
  double epsilon = 0.8;
  /// Stop choosing after this long (t_max); 0: no limit. A limit makes the
  /// selection depend on the machine's speed, so it is off by default.
  double time_budget_ms = 0.0;
  std::uint64_t seed = 1;  ///< the random draws; the same seed and input give the same selection
  std::size_t min_features = 50;  ///< never fewer (a near-empty frame keeps all it has)
  /// The result is checked on held_out_share x M of the features it did not
  /// use, searched at the final pose; when their mean |r| exceeds
  /// held_out_residual_ratio x the chosen ones' (plus held_out_residual_floor_m),
  /// the registration runs again on every feature. (Greedy picks the features
  /// with the largest information at the start pose; on real keyframes 0.5 s
  /// apart, where that pose can be 10-25 deg off, such a set once settled 13 deg
  /// wrong with a tight fit of its own: docs/benchmarks.md "Feature selection".)
  double held_out_share = 0.25;
  double held_out_residual_ratio = 1.5;
  double held_out_residual_floor_m = 0.01;
  /// Frames more than this long after the last registered one (lost frames between count as the gap) register every
  /// feature. The selection picks features by their information at the start pose, which the thesis has at 10 Hz;
  /// on real keyframes 0.5 s apart the chosen sets settled up to 1.15 deg off unflagged where every feature stayed
  /// within 0.35 deg (docs/benchmarks.md).
  double max_frame_gap_s = 0.25;
  /// Read by the SLAM estimator: whether the odometries select while an extrinsic is being calibrated (online or
  /// refine; their poses and map are the calibration's input: selecting there made convergence 26 % later on campus).
  bool while_calibrating = false;
};

/// Prior information delta that keeps log det finite for fewer than 6 features.
inline constexpr double kPriorInformation = 1e-6;

/// One feature's information Lambda_i = U U^T: its weighted Jacobian rows
/// (sqrt(w) j^T, [t, r] order), one column for a plane, two for an edge.
struct FeatureInformation {
  Eigen::Matrix<double, 6, 2> rows = Eigen::Matrix<double, 6, 2>::Zero();
  int rank = 1;  ///< 1 or 2 columns used
  Mat6 information() const;
};

/// log det(delta I + sum of the features' information).
double log_det_information(std::span<const FeatureInformation> features);

/// The degeneracy factors of the full feature set F.
struct Degeneracy {
  double log_det = 0.0;                    ///< the thesis's lambda = log det Lambda(F) (with delta I)
  double translation_observability = 0.0;  ///< lambda_min / lambda_max of Lambda(F)'s translation block, in [0, 1]
};
Degeneracy degeneracy_of(std::span<const FeatureInformation> features);
/// Sec 5.4.4 (with `adaptive`): the translation observability is below degeneracy_threshold.
bool degenerate_scene(const Degeneracy& full_set, const SelectionConfig& config);
/// M for `available` features: `ratio` (or `degenerate_ratio` in a degenerate scene) of them, at least min_features.
std::size_t selection_budget(std::size_t available, bool degenerate, const SelectionConfig& config);

/// Feature i's information, its correspondence searched on first use; nullptr when it has none.
using InformationSource = std::function<const FeatureInformation*(std::uint32_t)>;

struct SelectionResult {
  std::vector<std::uint32_t> chosen;  ///< feature indices, ascending
  double log_det = 0.0;               ///< log det Lambda(chosen) (with delta I)
  std::size_t visited = 0;            ///< features whose information was asked for (searched)
  std::size_t matched = 0;            ///< of those, the ones with a correspondence
  bool stopped_by_time = false;
};

/// Algorithm 2 over features 0 .. count-1 for `budget` of them (every matched
/// one when budget >= count). Deterministic for a seed unless the time budget stops it.
SelectionResult select_greedy(std::size_t count, std::size_t budget, const InformationSource& information, const SelectionConfig& config);
/// Features drawn uniformly without replacement until `budget` have a correspondence (the "rnd" baseline).
SelectionResult select_random(std::size_t count, std::size_t budget, const InformationSource& information, std::uint64_t seed);

}  // namespace mlidar::slam
