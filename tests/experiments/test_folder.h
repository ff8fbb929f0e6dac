// Test helpers for the end-to-end tests of the pldvo binary: a per-process scratch folder that is
// removed when the test process ends, reading a whole file, and running the binary (the including
// test target defines PLDVO_BINARY).
#ifndef PLDVO_TESTS_EXPERIMENTS_TEST_FOLDER_H_
#define PLDVO_TESTS_EXPERIMENTS_TEST_FOLDER_H_

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace pldvo::test {

// temp/pldvo_test_<pid>, created empty on first use and removed when the process ends.
inline std::filesystem::path TestRoot() {
  static const std::filesystem::path root = [] {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("pldvo_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
  }();
  return root;
}

class RemoveTestRoot : public ::testing::Environment {
 public:
  void TearDown() override { std::filesystem::remove_all(TestRoot()); }
};
[[maybe_unused]] inline ::testing::Environment* const kRemoveTestRoot =
    ::testing::AddGlobalTestEnvironment(new RemoveTestRoot);

inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

#ifdef PLDVO_BINARY
// Runs the pldvo binary with `args`; stdout and stderr go to `log`. Returns the exit code.
inline int Pldvo(const std::string& args, const std::filesystem::path& log) {
  const std::string command =
      std::string(PLDVO_BINARY) + " " + args + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
#endif

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_EXPERIMENTS_TEST_FOLDER_H_
