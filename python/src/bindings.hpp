#pragma once
// The parts of the module _mlidar, one function per file that adds them.
#include <functional>

#include <pybind11/pybind11.h>

namespace mlidar::python {

namespace py = pybind11;

void add_errors(py::module_& module);       ///< InputError, UsageError, OutputError and their translation
void add_clouds(py::module_& module);       ///< read_cloud, write_cloud, read_extrinsics
void add_frames(py::module_& module);       ///< FrameSource
void add_jobs(py::module_& module);         ///< odometry, slam, calibrate_auto
void add_eval(py::module_& module);         ///< eval_traj
void add_calibration(py::module_& module);  ///< calibrate_planes

/// A job's progress(done, total): calls `callback` (may be None) with the GIL held, and raises
/// KeyboardInterrupt in the job when Ctrl-C was pressed (the job's run folder is then removed, as the CLI's).
/// It borrows `callback`: use it only while the caller's reference lives (the call that made it).
std::function<void(int, int)> progress_function(const py::object& callback);

}  // namespace mlidar::python
