// Regression tests for the parser defects the fuzzers of tests/fuzz found
// (docs/reliability.md): each input once crashed, hung or hit undefined behaviour, and must now
// be rejected with a std::exception naming the file, while the valid spellings next to it are
// still read.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/camera_model.h"
#include "core/camera_yaml.h"
#include "core/config_io.h"
#include "core/dataset.h"
#include "core/dataset_util.h"
#include "core/pinhole_camera.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The message of the std::exception `f` throws, or "" if it does not throw.
std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

struct StringOptions {
  std::string name = "a";
  double value = 1.0;
  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("name", &name, "A string.");
    v.Field("value", &value, "A number.");
  }
};

class ParserRegressionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("pldvo_parser_regression_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string Write(const std::string& relative, const std::string& text) const {
    const fs::path path = root_ / relative;
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }

  fs::path root_;
};

constexpr char kCameraKeys[] =
    "model: pinhole\nwidth: 64\nheight: 48\nfx: 50\nfy: 50\ncx: 31.5\ncy: 23.5\ndistortion: []\n";

// cv::FileStorage (OpenCV 4.6) looped forever on these: a second YAML document starting with
// '-'. yaml-cpp would read the first document and drop the rest without a word; the
// one-document rule of core/yaml_reader.cc rejects them with the line.
TEST_F(ParserRegressionTest, YamlInputsThatHangOpenCvAreRejected) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"%YAML:1.0\n---L:1\n--x-\n\n", "after '---'"},  // the fuzzer's input, minimised
      {std::string("%YAML:1.0\n---\n") + kCameraKeys + "...\n- 1\n", "'...'"},
      {std::string("%YAML:1.0\n---\n") + kCameraKeys + "---\n- 1\n", "second '---'"},
      {"%YAML:1.0\n---\n  model: pinhole\nab\n-\n", "column 0"},
  };
  for (const auto& [text, what] : cases) {
    const std::string path = Write("camera.yaml", text);
    const std::string error = ErrorOf([&] { ReadCameraYaml(path); });
    EXPECT_THAT(error, HasSubstr(path)) << text;
    EXPECT_THAT(error, HasSubstr(what)) << text;
    StringOptions options;
    EXPECT_THAT(ErrorOf([&] { LoadConfigYaml(path, &options); }), HasSubstr(what)) << text;
  }
}

// yaml-cpp 0.7's LoadAll looped for ever, allocating, on a document that starts with ','
// (camera_yaml_fuzzer's input below, minimised; jbeder/yaml-cpp #1040). core/yaml_reader.cc asks
// the parser for two documents at most and names the line of the content it could not read.
TEST_F(ParserRegressionTest, YamlDocumentStartingWithACommaIsRejected) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {",", ":1: YAML syntax error"},
      {"%YAML 1.2\n---\n,\n", ":3: YAML syntax error"},
      {"%MALY:1.0\n,--\nmodel: fov\nwidth: 40\n", ":2: YAML syntax error"},
  };
  for (const auto& [text, what] : cases) {
    const std::string path = Write("camera.yaml", text);
    EXPECT_THAT(ErrorOf([&] { ReadCameraYaml(path); }), HasSubstr(path + what)) << text;
    StringOptions options;
    EXPECT_THAT(ErrorOf([&] { LoadConfigYaml(path, &options); }), HasSubstr(path + what)) << text;
  }
}

TEST_F(ParserRegressionTest, YamlSpellingsNextToTheGuardStillRead) {
  for (const std::string& text :
       {std::string("%YAML:1.0\n---\n") + kCameraKeys,
        std::string("%YAML:1.0\n--- # calibration\n") + kCameraKeys, std::string(kCameraKeys)}) {
    const std::string path = Write("camera.yaml", text);
    EXPECT_EQ(ErrorOf([&] { ReadCameraYaml(path); }), "") << text;
  }
}

// OpenCV's reader took "4294967936" for the int 640 (strtol, then a cast), and rejected a
// comment line before "---"; the yaml-cpp reader does neither.
TEST_F(ParserRegressionTest, YamlIntegersOutOfRangeAndCommentsBeforeTheMarker) {
  std::string text = kCameraKeys;
  text.replace(text.find("width: 64"), 9, "width: 4294967936");
  const std::string path = Write("camera.yaml", text);
  EXPECT_THAT(ErrorOf([&] { ReadCameraYaml(path); }), HasSubstr(path + ":2: key 'width'"));
  const std::string commented = Write("commented.yaml", std::string("# c\n---\n") + kCameraKeys);
  EXPECT_EQ(ErrorOf([&] { ReadCameraYaml(commented); }), "");
}

// An empty key in a nested map made cv::FileStorage throw std::length_error
// ("basic_string::_M_create"), which escaped without the file name (config_fuzzer). yaml-cpp
// reads it as a null key, which core/yaml_reader.cc rejects with the line.
TEST_F(ParserRegressionTest, EmptyNestedKeyIsAYamlErrorNamingTheFile) {
  const std::string path = Write("config.yaml", "%YAML:1.0\n---\nname:\n   ...x: 1\n   :\n");
  StringOptions options;
  const std::string error = ErrorOf([&] { LoadConfigYaml(path, &options); });
  EXPECT_THAT(error, HasSubstr(path + ":5: YAML syntax error"));
}

// WriteCameraYaml spelled cx = 19444444444444444.2 as "19444444444444444", which
// cv::FileStorage reads as a wrapped int (camera_yaml_fuzzer: the round trip broke).
TEST_F(ParserRegressionTest, CameraYamlWritesLargeValuesAsReals) {
  const PinholeCamera intrinsics{45, 30, 42.4, 21.07, 19444444444444444.2, 14.51};
  const std::string path = (root_ / "camera.yaml").string();
  WriteCameraYaml(*MakeCameraModel("fov", intrinsics, {0.897}), path);
  const std::unique_ptr<CameraModel> copy = ReadCameraYaml(path);
  EXPECT_EQ(copy->intrinsics().cx, intrinsics.cx);
  EXPECT_EQ(copy->intrinsics().fx, intrinsics.fx);
}

// An override string with a control character was accepted but written by WriteConfigYaml as
// YAML that cv::FileStorage rejects (config_fuzzer: the round trip broke).
TEST_F(ParserRegressionTest, OverrideWithControlCharacterIsRejected) {
  StringOptions options;
  EXPECT_THAT(ErrorOf([&] { ApplyOverrides({std::string("name=tum_\x1br3")}, &options); }),
              HasSubstr("control characters"));
  EXPECT_EQ(options.name, "a");
  ApplyOverrides({"name=with spaces, \"quotes\" and \\ backslash"}, &options);
  const std::string path = Write("config.yaml", ConfigToString(options));
  StringOptions copy;
  LoadConfigYaml(path, &copy);
  EXPECT_EQ(copy.name, options.name);
}

// A file's string with an escaped line break ("\n") was read, then written by ConfigToString as
// a raw line break that YAML folds into a space (config_fuzzer: the round trip broke).
TEST_F(ParserRegressionTest, FileStringWithControlCharacterIsRejected) {
  StringOptions options;
  const std::string path = Write("config.yaml", "name: \"tum_\\nfr3\"\n");
  EXPECT_THAT(ErrorOf([&] { LoadConfigYaml(path, &options); }),
              AllOf(HasSubstr(path), HasSubstr("control characters")));
  EXPECT_EQ(options.name, "a");
  LoadConfigYaml(Write("config.yaml", "name: \"tum \\\"fr3\\\" \\\\ \"\n"), &options);
  EXPECT_EQ(options.name, "tum \"fr3\" \\ ");
}

// A line of only '\v' or '\f' gave a table line without fields; the KITTI calib.txt reader
// indexed fields[0] of it (kitti_dataset_fuzzer: null reference, UBSan).
TEST_F(ParserRegressionTest, TableLinesWithoutFieldsAreSkipped) {
  const std::string path = Write("calib.txt", "\v\nP0: 1 2\n \f \n3\n");
  const std::vector<dataset_util::TableLine> table = dataset_util::ReadTable(path);
  ASSERT_EQ(table.size(), 2u);
  EXPECT_EQ(table[0].line_number, 2);
  EXPECT_EQ(table[1].line_number, 4);
}

// resolution: [1e10, 24] was cast to int (undefined behaviour, UBSan float-cast-overflow).
TEST_F(ParserRegressionTest, EurocResolutionOutOfIntRangeIsRejected) {
  Write("mav0/cam0/data.csv", "1403636579763555584,a.png\n");
  for (const char* resolution : {"[1e10, 24]", "[32.5, 24]", "[-32, 24]"}) {
    const std::string sensor = Write(
        "mav0/cam0/sensor.yaml",
        "T_BS:\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\nresolution: " +
            std::string(resolution) +
            "\ncamera_model: pinhole\nintrinsics: [30, 30, 15.5, 11.5]\ndistortion_model: none\n");
    DatasetOptions options;
    options.format = "euroc";
    const std::string error = ErrorOf([&] { OpenDataset(root_.string(), options); });
    EXPECT_THAT(error, HasSubstr(sensor + ":3: resolution must be two positive integers"))
        << resolution;
  }
}

// Image sizes from calibration files are bounded: camera.txt with a width of 2e9 and "full"
// hung in the border scan, and 100000x100000 output maps exhausted memory.
TEST_F(ParserRegressionTest, HugeImageSizesAreRejected) {
  PinholeCamera camera{7680, 4320, 5000.0, 5000.0, 3839.5, 2159.5};  // 8K UHD: supported
  EXPECT_EQ(camera.Check(), "");
  for (const auto& [width, height] :
       std::vector<std::pair<int, int>>{{32769, 10}, {10, 40000}, {8192, 8192}}) {
    camera.width = width;
    camera.height = height;
    EXPECT_THAT(camera.Check(), HasSubstr("exceeds the supported")) << width << "x" << height;
  }
  EXPECT_THAT(
      ErrorOf([] {
        MakeCameraModel("pinhole", PinholeCamera{2000000000, 30, 30.0, 30.0, 19.5, 14.5}, {});
      }),
      HasSubstr("exceeds the supported"));
}

}  // namespace
}  // namespace pldvo
