#include "mlidar/sim/staged_folder.hpp"

#include <random>
#include <string>

#include "mlidar/core/error.hpp"

namespace mlidar::sim {

namespace fs = std::filesystem;

StagedFolder::StagedFolder(fs::path destination) : destination_(std::move(destination)) {
  std::error_code ec;
  if (destination_.filename().empty()) destination_ = destination_.parent_path();
  if (fs::exists(destination_, ec) && !(fs::is_directory(destination_, ec) && fs::is_empty(destination_, ec))) {
    throw UsageError(destination_.string() + ": the output folder exists and is not empty (choose a new --out folder or remove it)");
  }
  const fs::path parent = destination_.has_parent_path() ? destination_.parent_path() : fs::path(".");
  fs::create_directories(parent, ec);
  if (ec) throw UsageError(parent.string() + ": cannot create the output's parent folder: " + ec.message());
  std::random_device device;
  staging_ = parent / (destination_.filename().string() + ".tmp-" + std::to_string(device()));
  if (!fs::create_directory(staging_, ec) || ec) {
    throw UsageError(parent.string() + ": cannot write in this folder: " + (ec ? ec.message() : "temporary folder exists"));
  }
}

StagedFolder::~StagedFolder() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagedFolder::commit() {
  std::error_code ec;
  if (fs::is_directory(destination_, ec)) fs::remove(destination_, ec);  // empty, checked at construction
  fs::rename(staging_, destination_, ec);
  if (ec) throw OutputError(destination_.string() + ": cannot move the finished dataset into place: " + ec.message());
  committed_ = true;
}

}  // namespace mlidar::sim
