// The extension module mlidar._mlidar: mlidar's C++ library for Python (python/mlidar wraps it).
#include <exception>
#include <string>

#include "bindings.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/core/heap_settings.hpp"
#include "mlidar/core/version.hpp"

namespace mlidar::python {
namespace {

/// Raises mlidar._mlidar.`type_name`(message) with the attributes `file` and `field` (empty where none).
void raise_error(const char* type_name, const char* message, const std::string& file, const std::string& field) {
  const py::object type = py::module_::import("mlidar._mlidar").attr(type_name);
  const py::object error = type(message);
  error.attr("file") = file;
  error.attr("field") = field;
  PyErr_SetObject(type.ptr(), error.ptr());
}

void translate_error(std::exception_ptr thrown) {
  try {
    if (thrown) std::rethrow_exception(thrown);
  } catch (const InputError& e) {
    raise_error("InputError", e.what(), e.file(), e.field());
  } catch (const UsageError& e) {
    raise_error("UsageError", e.what(), "", "");
  } catch (const OutputError& e) {
    raise_error("OutputError", e.what(), "", "");
  }
}

}  // namespace

void add_errors(py::module_& module) {
  py::exception<InputError>(module, "InputError", PyExc_ValueError).doc() =
      "Bad input data or configuration (the CLI's exit 3): `file` and `field` name where, the message what and the fix.";
  py::exception<UsageError>(module, "UsageError", PyExc_ValueError).doc() =
      "Options that cannot be acted on (the CLI's exit 2), e.g. an output folder that may not be replaced.";
  py::exception<OutputError>(module, "OutputError", PyExc_OSError).doc() = "An output could not be written (disk full, no permission).";
  py::register_exception_translator(&translate_error);
}

std::function<void(int, int)> progress_function(const py::object& callback) {
  const py::handle borrowed = callback;  // no reference counting when the job copies the function without the GIL
  return [borrowed](int done, int total) {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C: the job stops, its run folder is removed
    if (!borrowed.is_none()) borrowed(done, total);
  };
}

}  // namespace mlidar::python

PYBIND11_MODULE(_mlidar, module) {
  module.doc() = "mlidar's C++ library: clouds, frame sources, odometry, SLAM, calibration and evaluation";
  module.attr("__version__") = mlidar::kVersion;
  mlidar::python::add_errors(module);
  mlidar::python::add_clouds(module);
  mlidar::python::add_frames(module);
  mlidar::python::add_jobs(module);
  mlidar::python::add_eval(module);
  mlidar::python::add_calibration(module);
  module.def("keep_large_buffers_in_the_heap", &mlidar::keep_large_buffers_in_the_heap,
             "What the CLI's main does (core/heap_settings.hpp): large buffers stay in the heap; a job's worker calls it");
}
