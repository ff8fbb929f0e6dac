// Helpers shared by the libFuzzer targets of tests/fuzz (docs/reliability.md): a private
// scratch folder per fuzzing process, file writing, and the outcome policy.
//
// Outcome policy: a parser may reject any input by throwing a std::exception (the normal
// outcome for malformed input); the message must then name the file at fault. Findings, which
// abort the process so that libFuzzer saves the input, are:
//   - crashes, sanitizer reports, hangs (-timeout), allocations over -rss_limit_mb;
//   - a cv::Exception escaping (the contract is std::runtime_error / std::invalid_argument with
//     the file and line, not OpenCV's message);
//   - any exception not derived from std::exception (it escapes and libFuzzer reports it);
//   - a std::exception whose message does not name the file (FailUnlessNamed);
//   - a target-specific invariant violated on accepted input (Require).
#ifndef PLDVO_TESTS_FUZZ_FUZZ_UTIL_H_
#define PLDVO_TESTS_FUZZ_FUZZ_UTIL_H_

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <system_error>

namespace pldvo {
namespace fuzz {

// A folder private to this process, created on first use and removed at exit.
inline const std::string& ScratchDir() {
  static const std::string dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/pldvo_fuzz_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("mkdtemp");
      std::abort();
    }
    static std::string to_remove;
    to_remove = pattern;
    std::atexit([] {
      std::error_code error;
      std::filesystem::remove_all(to_remove, error);
    });
    return pattern;
  }();
  return dir;
}

// Creates the parent folders and writes `size` bytes (truncating).
inline void WriteFile(const std::string& path, const uint8_t* data, size_t size) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

inline void WriteFile(const std::string& path, const std::string& text) {
  WriteFile(path, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

[[noreturn]] inline void Finding(const std::string& what) {
  std::fprintf(stderr, "\n==pldvo-fuzz== FINDING: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// An invariant of accepted input.
inline void Require(bool condition, const std::string& what) {
  if (!condition) Finding("invariant violated: " + what);
}

// Runs `parse`; a std::exception is a normal outcome when its message contains `must_name`
// (the folder or file at fault; empty: any message). Returns true when parse returned.
template <typename Parse>
bool RunParser(Parse&& parse, const std::string& must_name) {
  try {
    parse();
    return true;
  } catch (const cv::Exception& error) {
    Finding(std::string("cv::Exception escaped the parser: ") + error.what());
  } catch (const std::exception& error) {
    const std::string message = error.what();
    if (!must_name.empty() && message.find(must_name) == std::string::npos) {
      Finding("error message does not name '" + must_name + "': " + message);
    }
  }
  return false;
}

}  // namespace fuzz
}  // namespace pldvo

#endif  // PLDVO_TESTS_FUZZ_FUZZ_UTIL_H_
