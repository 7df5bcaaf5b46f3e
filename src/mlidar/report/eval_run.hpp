#pragma once
// `eval traj --out RUN`: eval.json, the associated pairs as groundtruth.tum and
// trajectory.tum (the estimate before alignment, at the ground truth's stamps,
// so the report re-associates them exactly) and report.html, committed
// together as one run folder (io/run_folder.hpp).
#include <filesystem>

#include "mlidar/eval/trajectory_files.hpp"
#include "mlidar/io/run_folder.hpp"

namespace mlidar::report {

void write_eval_run(const std::filesystem::path& out, const eval::TrajectoryFileEvaluation& evaluation, io::RunFolderOptions options);

}  // namespace mlidar::report
