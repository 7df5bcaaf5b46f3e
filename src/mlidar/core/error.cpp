#include "mlidar/core/error.hpp"

namespace mlidar {
namespace {
std::string compose(const std::string& file, const std::string& field, const std::string& problem) {
  std::string message = file.empty() ? std::string("<input>") : file;
  if (!field.empty()) message += ": " + field;
  return message + ": " + problem;
}
}  // namespace

InputError::InputError(const std::string& file, const std::string& field, const std::string& problem)
    : std::runtime_error(compose(file, field, problem)), file_(file), field_(field) {}

}  // namespace mlidar
