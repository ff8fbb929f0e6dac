// Test helper: synthetic frames and sequence folders rendered once per ctest run and shared by the
// test processes.
//
// ctest runs every TEST in its own process, and the end-to-end suites render the same frames in
// each of them (about half of their time under the sanitizers, docs/reliability.md). ctest sets
// PLDVO_TEST_RENDER_CACHE to a folder that a fixture empties before the run and removes after it
// (tests/CMakeLists.txt), so nothing cached outlives the binaries that rendered it. Without the
// variable (a test binary run by hand) everything is rendered.
#ifndef PLDVO_TESTS_RENDER_CACHE_H_
#define PLDVO_TESTS_RENDER_CACHE_H_

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "core/config_io.h"
#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::test {

namespace render_cache_internal {

// An exclusive flock on `path` for the scope: the first process renders a frame while the
// others wait for it instead of rendering it too.
class FileLock {
 public:
  explicit FileLock(const std::filesystem::path& path)
      : fd_(::open(path.c_str(), O_RDWR | O_CREAT, 0644)) {
    if (fd_ >= 0) ::flock(fd_, LOCK_EX);
  }
  ~FileLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_;
};

// File layout: int32 rows, int32 cols, then the CV_8U image and the CV_32F depth, row-major.
inline bool ReadFrame(const std::filesystem::path& path, int rows, int cols,
                      synthetic::RenderedFrame* frame) {
  std::ifstream file(path, std::ios::binary);
  int32_t size[2] = {0, 0};
  if (!file.read(reinterpret_cast<char*>(size), sizeof(size)) || size[0] != rows ||
      size[1] != cols) {
    return false;
  }
  frame->image.create(rows, cols, CV_8U);
  frame->depth.create(rows, cols, CV_32F);
  file.read(reinterpret_cast<char*>(frame->image.data), frame->image.total());
  file.read(reinterpret_cast<char*>(frame->depth.data), frame->depth.total() * sizeof(float));
  return static_cast<bool>(file);
}

// Written to a temporary file and renamed, so a reader never sees a partial frame.
inline void WriteFrame(const std::filesystem::path& path, const synthetic::RenderedFrame& frame) {
  const std::filesystem::path partial = path.string() + ".partial" + std::to_string(::getpid());
  {
    std::ofstream file(partial, std::ios::binary);
    const int32_t size[2] = {frame.image.rows, frame.image.cols};
    file.write(reinterpret_cast<const char*>(size), sizeof(size));
    file.write(reinterpret_cast<const char*>(frame.image.data), frame.image.total());
    file.write(reinterpret_cast<const char*>(frame.depth.data),
               frame.depth.total() * sizeof(float));
    if (!file) return;  // a full disk only costs the cache
  }
  std::error_code error;
  std::filesystem::rename(partial, path, error);
}

// The cache key of a set of synthesis options: a hash of all of them.
inline std::string OptionsKey(const synthetic::SynthOptions& options) {
  return std::to_string(std::hash<std::string>()(ConfigToString(options)));
}

// $PLDVO_TEST_RENDER_CACHE, or an empty path when it is not set.
inline std::filesystem::path CacheDirFromEnvironment() {
  const char* cache_dir = std::getenv("PLDVO_TEST_RENDER_CACHE");
  return cache_dir == nullptr ? std::filesystem::path() : std::filesystem::path(cache_dir);
}

// `dir`, created if needed, with an exclusive lock on `dir`/`lock_name` held by `lock`.
inline std::filesystem::path LockedDir(const std::filesystem::path& dir,
                                       const std::string& lock_name,
                                       std::unique_ptr<FileLock>* lock) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  *lock = std::make_unique<FileLock>(dir / lock_name);
  return dir;
}

}  // namespace render_cache_internal

// synthetic::RenderFrame(sequence, index), stored in and read from `cache_dir` (created if
// needed), keyed by every synthesis option and the frame index.
inline synthetic::RenderedFrame RenderFrameCached(const synthetic::SyntheticSequence& sequence,
                                                  int index,
                                                  const std::filesystem::path& cache_dir) {
  namespace internal = render_cache_internal;
  const std::string key = internal::OptionsKey(sequence.options) + "_" + std::to_string(index);
  std::unique_ptr<internal::FileLock> lock;
  const std::filesystem::path path =
      internal::LockedDir(cache_dir, key + ".lock", &lock) / (key + ".frame");
  synthetic::RenderedFrame frame;
  if (internal::ReadFrame(path, sequence.camera.height, sequence.camera.width, &frame)) {
    return frame;
  }
  frame = synthetic::RenderFrame(sequence, index);
  internal::WriteFrame(path, frame);
  return frame;
}

// RenderFrameCached in $PLDVO_TEST_RENDER_CACHE when it is set, else synthetic::RenderFrame.
inline synthetic::RenderedFrame RenderFrameForTest(const synthetic::SyntheticSequence& sequence,
                                                   int index) {
  const std::filesystem::path cache_dir = render_cache_internal::CacheDirFromEnvironment();
  if (cache_dir.empty()) return synthetic::RenderFrame(sequence, index);
  return RenderFrameCached(sequence, index, cache_dir);
}

// synthetic::WriteSequence(MakeSequence(options)) into $PLDVO_TEST_RENDER_CACHE/<key>/<name of
// `folder`>, once per ctest run, when the variable is set, else into `folder` unless it exists;
// returns the folder written. Callers copy it before changing anything in it.
inline std::filesystem::path SequenceFolderForTest(const synthetic::SynthOptions& options,
                                                   const std::filesystem::path& folder) {
  namespace internal = render_cache_internal;
  const std::filesystem::path cache_dir = internal::CacheDirFromEnvironment();
  if (cache_dir.empty()) {
    if (!std::filesystem::is_directory(folder)) {
      synthetic::WriteSequence(synthetic::MakeSequence(options), folder.string());
    }
    return folder;
  }
  std::unique_ptr<internal::FileLock> lock;
  const std::filesystem::path parent =
      internal::LockedDir(cache_dir / internal::OptionsKey(options), "lock", &lock);
  // The folder keeps the name of `folder`: the runs name the sequence after it.
  const std::filesystem::path cached = parent / folder.filename();
  if (std::filesystem::is_directory(cached)) return cached;
  // Written beside and renamed, so a folder in the cache is always complete.
  const std::filesystem::path partial = cached.string() + ".partial";
  std::filesystem::remove_all(partial);
  synthetic::WriteSequence(synthetic::MakeSequence(options), partial.string());
  std::filesystem::rename(partial, cached);
  return cached;
}

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_RENDER_CACHE_H_
