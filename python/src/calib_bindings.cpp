// calibrate_planes: `mlidar calibrate planes` (PS-Calib from a wall corner seen by two LiDARs).
#include <string>

#include <pybind11/stl/filesystem.h>

#include "array_views.hpp"
#include "bindings.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/pipelines/planes_job.hpp"

namespace mlidar::python {

void add_calibration(py::module_& module) {
  module.def(
      "calibrate_planes",
      [](const std::filesystem::path& ref, const std::filesystem::path& target, const std::filesystem::path& init,
         const std::filesystem::path& config, const std::filesystem::path& out, const std::filesystem::path& report) {
        std::string json;
        pipelines::PlanesJobResult job;
        {
          py::gil_scoped_release release;
          if (!out.empty()) io::check_output_file(out, "out");
          if (!report.empty()) io::check_output_file(report, "report");
          job = pipelines::run_planes_job({ref, target, init, config});
          const nlohmann::json report_json = pipelines::planes_report_json(job);
          if (!out.empty()) io::write_extrinsics(out, pipelines::planes_extrinsics(job));
          json = report_json.dump();
          if (!report.empty()) io::write_atomically(report, [&](std::ostream& stream) { stream << report_json.dump(2) << '\n'; });
        }
        py::dict result = py::module_::import("json").attr("loads")(json);
        result["T_ref_target_matrix"] = matrix_array(job.result.T_ref_target);
        result["covariance_matrix"] = dense_array(job.result.covariance);
        result["ref_name"] = job.ref_name;
        result["target_name"] = job.target_name;
        return result;
      },
      py::arg("ref"), py::arg("target"), py::kw_only(), py::arg("init") = "", py::arg("config") = "", py::arg("out") = "",
      py::arg("report") = "",
      "`mlidar calibrate planes`: T_ref_target from a wall corner seen in both clouds, as --report's JSON (verdict, "
      "warnings, T_ref_target, covariance, residuals, planes) plus T_ref_target_matrix (4x4) and covariance_matrix "
      "(6x6, [t, r]); `out` writes the pair's extrinsics YAML, `report` the JSON.");
}

}  // namespace mlidar::python
