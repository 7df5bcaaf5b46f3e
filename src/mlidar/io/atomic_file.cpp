#include "mlidar/io/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <streambuf>
#include <string>
#include <thread>

#include "mlidar/core/error.hpp"
#include "mlidar/io/interrupt_cleanup.hpp"

namespace mlidar::io {
namespace {

/// A std::streambuf writing to a POSIX file descriptor; failed writes (disk full) set the stream's badbit.
class FdBuffer : public std::streambuf {
 public:
  explicit FdBuffer(int fd) : fd_(fd) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!flush_buffer()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return flush_buffer() ? 0 : -1; }

 private:
  bool flush_buffer() {
    const char* data = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    while (left > 0) {
      const ssize_t written = ::write(fd_, data, left);
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0) {
        error_ = written < 0 ? errno : ENOSPC;
        return false;
      }
      data += written;
      left -= static_cast<std::size_t>(written);
    }
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return true;
  }

  int fd_;
  int error_ = 0;
  std::array<char, 1 << 16> buffer_{};
};

std::filesystem::path temporary_name(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return tmp;
}

/// Removes PATH.tmp-PID-N files of processes that no longer run.
void remove_stale_temporaries(const std::filesystem::path& path) {
  const std::string prefix = path.filename().string() + ".tmp-";
  std::error_code ec;
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) std::filesystem::remove(entry.path(), ec);
  }
}

std::string system_message(int error) { return std::strerror(error); }

}  // namespace

bool test_pause(const char* point) {
  const char* wanted = std::getenv("MLIDAR_TEST_PAUSE");
  if (wanted == nullptr || std::strcmp(wanted, point) != 0) return false;
  std::cerr << "mlidar: test pause before rename" << std::endl;
  std::this_thread::sleep_for(std::chrono::seconds(30));
  return true;
}

void sync_path(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(path.string() + ": cannot open to flush it to disk: " + system_message(errno));
  const int result = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  // Some file systems cannot sync a folder (EINVAL): the rename is still atomic there.
  if (result != 0 && error != EINVAL) throw OutputError(path.string() + ": cannot flush to disk: " + system_message(error));
}

/// Inside a run folder's staging folder: straight to `path`, the commit flushes and publishes the folder whole.
void write_in_staging(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw OutputError(path.string() + ": cannot create a file in this folder (" + system_message(errno) + ")");
  write(out);
  out.flush();
  if (!out) throw OutputError(path.string() + ": write failed (" + system_message(errno) + ")");
}

void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write) {
  if (inside_unfinished_folder(path)) return write_in_staging(path, write);
  remove_stale_temporaries(path);
  const UnfinishedOutput tmp(temporary_name(path));
  try {
    const int fd = ::open(tmp.path().c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0)
      throw OutputError(path.string() + ": cannot create a file in this folder (" + system_message(errno) +
                        "; check that it exists and is writable)");
    FdBuffer buffer(fd);
    std::ostream out(&buffer);
    bool ok = false;
    try {
      write(out);
      out.flush();
      ok = static_cast<bool>(out) && ::fsync(fd) == 0;
    } catch (...) {
      ::close(fd);
      throw;
    }
    const int error = buffer.error() != 0 ? buffer.error() : errno;
    if (::close(fd) != 0 || !ok) throw OutputError(path.string() + ": write failed (" + system_message(error) + ")");
    test_pause("file");
    {
      const auto lock = lock_unfinished_outputs();
      std::error_code ec;
      std::filesystem::rename(tmp.path(), path, ec);
      if (ec) throw OutputError(path.string() + ": cannot rename the finished file into place: " + ec.message());
    }
    sync_path(path.has_parent_path() ? path.parent_path() : ".");
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp.path(), ignored);
    throw;
  }
}

void check_output_file(const std::filesystem::path& path, const std::string& option) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw UsageError(option + " " + path.string() + ": is a folder; give a file name");
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  if (!std::filesystem::is_directory(folder, ec))
    throw UsageError(option + " " + path.string() + ": its folder " + folder.string() + " does not exist (create it first)");
  if (::access(folder.c_str(), W_OK) != 0)
    throw UsageError(option + " " + path.string() + ": its folder " + folder.string() + " is not writable (" + system_message(errno) + ")");
}

}  // namespace mlidar::io
