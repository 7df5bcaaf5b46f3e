#include "mlidar/report/eval_run.hpp"

#include <vector>

#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/report/run_report.hpp"

namespace mlidar::report {
namespace {

/// Poses stamped with the ground truth's stamps of their association (a KITTI file's poses get its index stamps).
Trajectory stamped(const std::vector<SE3>& poses, const std::vector<double>& stamps) {
  Trajectory out;
  for (std::size_t i = 0; i < poses.size(); ++i) out.poses.push_back({stamps[i], poses[i]});
  return out;
}

}  // namespace

void write_eval_run(const std::filesystem::path& out, const eval::TrajectoryFileEvaluation& evaluation, io::RunFolderOptions options) {
  io::RunFolder run(out, "eval traj", std::move(options));
  const std::string text = evaluation.json.dump(2);
  io::write_atomically(run / "eval.json", [&](std::ostream& stream) { stream << text << '\n'; });
  io::write_tum(run / "groundtruth.tum", stamped(evaluation.report.gt, evaluation.report.stamps));
  io::write_tum(run / "trajectory.tum", stamped(evaluation.report.est, evaluation.report.stamps));
  write_run_report(run.path(), {"eval traj", {}, out});
  run.commit();
}

}  // namespace mlidar::report
