// FrameSource: a dataset folder, a folder of one LiDAR's clouds or a bag, frame by frame (io/frame_source.hpp);
// doctor: `mlidar doctor` on one of them.
#include <optional>
#include <string>
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "array_views.hpp"
#include "bindings.hpp"
#include "mlidar/io/bag_frames.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/pipelines/dataset_doctor.hpp"
#include "mlidar/sim/lidar_models.hpp"

namespace mlidar::python {
namespace {

py::dict frame_dict(const io::FrameSource& source, io::SourceFrame frame) {
  py::dict scans;
  for (std::size_t j = 0; j < frame.scans.size(); ++j) {
    const std::string& name = source.lidars()[j].name;
    if (frame.scans[j]) {
      scans[py::str(name)] = scan_arrays(std::move(*frame.scans[j]));
    } else {
      scans[py::str(name)] = py::none();
    }
  }
  py::list skipped;
  for (const io::SkippedScan& gap : frame.skipped) {
    py::dict entry;
    entry["lidar"] = source.lidars()[gap.lidar].name;
    entry["reason"] = io::to_string(gap.reason);
    entry["file"] = gap.file;
    entry["detail"] = gap.detail;
    skipped.append(entry);
  }
  py::dict out;
  out["index"] = frame.index;
  out["stamp"] = frame.stamp;
  out["scans"] = scans;
  out["skipped"] = skipped;
  return out;
}

py::dict frame_at(const io::FrameSource& source, py::ssize_t k) {
  const auto frames = static_cast<py::ssize_t>(source.frames());
  if (k < 0) k += frames;
  if (k < 0 || k >= frames) throw py::index_error("frame " + std::to_string(k) + " of " + std::to_string(frames));
  io::SourceFrame frame;
  {
    py::gil_scoped_release release;
    frame = source.read(static_cast<std::size_t>(k));
  }
  return frame_dict(source, std::move(frame));
}

py::dict lidar_dict(const io::SourceLidar& lidar) {
  py::dict out;
  out["name"] = lidar.name;
  out["model"] = lidar.model.name;
  out["rings"] = lidar.model.rings();
  out["T_base_lidar"] = lidar.initial_extrinsic ? py::object(matrix_array(*lidar.initial_extrinsic)) : py::object(py::none());
  return out;
}

}  // namespace

void add_frames(py::module_& module) {
  py::class_<io::FrameSource>(module, "FrameSource",
                              "The frames of a recording: per frame the stamp and each LiDAR's scan (None where it has none). "
                              "Index it, or iterate; each cloud is parsed when its frame is read.")
      .def_static(
          "dataset",
          [](const std::filesystem::path& folder, const std::vector<std::string>& lidars) {
            return io::FrameSource::dataset(folder, lidars);
          },
          py::arg("folder"), py::arg("lidars") = std::vector<std::string>{},
          "A dataset folder (dataset.yaml, times.txt, scans/); `lidars` picks some of its LiDARs by name.")
      .def_static(
          "scans",
          [](const std::filesystem::path& folder, double period, const std::optional<std::filesystem::path>& times,
             const std::string& model) {
            return io::FrameSource::scan_folder(folder, period, times, model.empty() ? LidarModel{} : sim::lidar_model(model));
          },
          py::arg("folder"), py::arg("period") = 0.1, py::arg("times") = py::none(), py::arg("model") = "",
          "A folder of one LiDAR's clouds in natural order, `period` seconds apart or at the stamps of the file `times`; "
          "`model` names its LiDAR (e.g. 'OS1-64') as `odometry --model` does.")
      .def_static(
          "bag",
          [](const std::filesystem::path& path, const std::string& topics, const std::string& base, const std::string& stamp_at,
             const std::string& extrinsics, const std::string& models, double start, double duration) {
            const io::BagArguments arguments{path.string(), topics, base, stamp_at, extrinsics, models, start, duration};
            return io::FrameSource::bag(path, io::bag_source_options(arguments));
          },
          py::arg("path"), py::arg("topics") = "", py::arg("base") = "", py::arg("stamp_at") = "auto", py::arg("extrinsics") = "",
          py::arg("models") = "", py::arg("start") = 0.0, py::arg("duration") = 0.0,
          "A ROS 1 bag, an MCAP file or a rosbag2 folder; the keywords are the CLI's --topics, --base, --stamp-at, "
          "--extrinsics, --models, --start and --duration.")
      .def("__len__", &io::FrameSource::frames)
      .def("__getitem__", &frame_at, py::arg("k"))
      .def_property_readonly("lidars",
                             [](const io::FrameSource& source) {
                               py::list out;
                               for (const io::SourceLidar& lidar : source.lidars()) out.append(lidar_dict(lidar));
                               return out;
                             })
      .def_property_readonly("stamps", [](const io::FrameSource& source) { return py::array(py::cast(source.stamps())); })
      .def_property_readonly("period", &io::FrameSource::period)
      .def_property_readonly("notes", &io::FrameSource::notes);
  module.def(
      "doctor",
      [](const std::filesystem::path& input, const std::string& topics, const std::string& base, const std::string& stamp_at,
         const std::string& extrinsics, const std::string& models) {
        std::string json;
        {
          py::gil_scoped_release release;
          const io::BagArguments bag{"", topics, base, stamp_at, extrinsics, models, 0.0, 0.0};
          json = pipelines::doctor_json(input.string(), pipelines::examine_input(input, bag)).dump();
        }
        return py::module_::import("json").attr("loads")(json);
      },
      py::arg("input"), py::kw_only(), py::arg("topics") = "", py::arg("base") = "", py::arg("stamp_at") = "auto",
      py::arg("extrinsics") = "", py::arg("models") = "",
      "`mlidar doctor`: a dataset folder or bag checked before a long run, as `doctor --json`'s dict {input, failed, "
      "findings: [{check, lidar, severity, message}]}; failed is the CLI's exit 1.");
}

}  // namespace mlidar::python
