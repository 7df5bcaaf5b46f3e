// eval_traj: `mlidar eval traj` on two trajectory files; the dict is eval.json's.
#include <string>
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/eval/trajectory_files.hpp"
#include "mlidar/report/eval_run.hpp"

namespace mlidar::python {

void add_eval(py::module_& module) {
  module.def(
      "eval_traj",
      [](const std::filesystem::path& gt, const std::filesystem::path& est, const std::string& format, const std::string& align,
         double max_dt, double delta, const std::string& delta_unit, const std::filesystem::path& covariance,
         const std::filesystem::path& out, bool overwrite, const std::vector<std::string>& arguments) {
        if (delta_unit != "frames" && delta_unit != "m") throw UsageError("--delta-unit is '" + delta_unit + "': use frames or m");
        eval::TrajectoryEvalOptions options;
        options.align = eval::parse_align_mode(align);
        options.max_dt = max_dt;
        options.delta = delta;
        options.delta_unit = delta_unit == "m" ? eval::DeltaUnit::kMeters : eval::DeltaUnit::kFrames;
        std::string json;
        {
          py::gil_scoped_release release;
          const eval::TrajectoryFileEvaluation evaluation = eval::evaluate_trajectory_files({gt, est, format, covariance}, options);
          if (!out.empty()) {
            std::vector<std::filesystem::path> inputs{gt, est};
            if (!covariance.empty()) inputs.push_back(covariance);
            report::write_eval_run(out, evaluation, {overwrite, inputs, arguments});
          }
          json = evaluation.json.dump();
        }
        return py::module_::import("json").attr("loads")(json);
      },
      py::arg("gt"), py::arg("est"), py::kw_only(), py::arg("format") = "", py::arg("align") = "se3", py::arg("max_dt") = 0.01,
      py::arg("delta") = 1.0, py::arg("delta_unit") = "frames", py::arg("covariance") = "", py::arg("out") = "",
      py::arg("overwrite") = false, py::arg("arguments") = std::vector<std::string>{});
}

}  // namespace mlidar::python
