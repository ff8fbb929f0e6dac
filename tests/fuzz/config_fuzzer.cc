// libFuzzer target: config YAML and `--set` overrides (core/config_io.h LoadConfigYaml,
// ApplyOverrides) over real options structs: the line frontend's (sections, enum choices, bool,
// int, double), the dataset's (strings) and the evaluation's, plus a list-of-double field so
// that every field type is reached.
// Input: the YAML file, optionally followed by a line "--set" and one override per line.
// On accepted input: ConfigToString reads back to the same config (the header's contract), and
// DescribeConfig and the core Check()s run.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/config_io.h"
#include "core/dataset.h"
#include "core/evaluation.h"
#include "frontend/line_frontend_options.h"
#include "tests/fuzz/fuzz_util.h"

namespace pldvo {
namespace {

struct FuzzConfig {
  LineFrontendOptions frontend;
  DatasetOptions dataset;
  EvaluationOptions evaluation;
  std::vector<double> weights = {1.0, 0.5};
  bool verbose = false;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Section("frontend", &frontend, "Line frontend.");
    v.Section("dataset", &dataset, "Dataset.");
    v.Section("evaluation", &evaluation, "Evaluation.");
    v.Field("weights", &weights, "A list of doubles.");
    v.Field("verbose", &verbose, "A bool at the top level.");
  }
};

}  // namespace
}  // namespace pldvo

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n--set\n";
  const size_t split = input.find(separator);
  const std::string yaml = input.substr(0, split);
  std::vector<std::string> overrides;
  if (split != std::string::npos) {
    size_t begin = split + separator.size();
    while (begin <= input.size()) {
      size_t end = input.find('\n', begin);
      if (end == std::string::npos) end = input.size();
      if (end > begin) overrides.push_back(input.substr(begin, end - begin));
      begin = end + 1;
    }
  }

  const std::string path = fuzz::ScratchDir() + "/config.yaml";
  fuzz::WriteFile(path, yaml);
  FuzzConfig config;
  if (!fuzz::RunParser([&] { LoadConfigYaml(path, &config); }, path)) return 0;
  // Override errors name the override, not a file.
  if (!fuzz::RunParser([&] { ApplyOverrides(overrides, &config); }, "override '")) return 0;

  const std::string text = ConfigToString(config);
  const std::string copy_path = fuzz::ScratchDir() + "/config_copy.yaml";
  fuzz::WriteFile(copy_path, text);
  FuzzConfig copy;
  if (!fuzz::RunParser([&] { LoadConfigYaml(copy_path, &copy); }, "")) {
    fuzz::Finding("ConfigToString output is rejected by LoadConfigYaml:\n" + text);
  }
  fuzz::Require(ConfigToString(copy) == text, "ConfigToString does not read back:\n" + text);
  DescribeConfig(config);
  config.dataset.Check();
  config.evaluation.Check();
  return 0;
}
