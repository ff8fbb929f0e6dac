#include "core/camera_yaml.h"

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <string>

namespace pldvo {
namespace {

std::string TempPath(const std::string& name) {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return ::testing::TempDir() + "pldvo_camera_yaml_" + info->name() + "_" + name;
}

std::string WriteFile(const std::string& name, const std::string& content) {
  const std::string path = TempPath(name);
  std::ofstream(path) << content;
  return path;
}

// The error message of reading `content`, or "no exception".
std::string ReadError(const std::string& path) {
  try {
    ReadCameraYaml(path);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "no exception";
}

const char kValid[] =
    "%YAML:1.0\n---\nmodel: radtan\nwidth: 640\nheight: 480\nfx: 517.3\nfy: 516.5\n"
    "cx: 318.6\ncy: 255.3\ndistortion: [0.2624, -0.9531, -0.0054, 0.0026, 1.1633]\n";

void ExpectSameCamera(const CameraModel& a, const CameraModel& b) {
  EXPECT_EQ(a.model_name(), b.model_name());
  EXPECT_EQ(a.intrinsics().width, b.intrinsics().width);
  EXPECT_EQ(a.intrinsics().height, b.intrinsics().height);
  // Exact: the writer prints the shortest decimal that reads back to the same double.
  EXPECT_EQ(a.intrinsics().fx, b.intrinsics().fx);
  EXPECT_EQ(a.intrinsics().fy, b.intrinsics().fy);
  EXPECT_EQ(a.intrinsics().cx, b.intrinsics().cx);
  EXPECT_EQ(a.intrinsics().cy, b.intrinsics().cy);
  EXPECT_EQ(a.distortion(), b.distortion());
}

TEST(CameraYamlTest, PresetsCarryTheTumCalibrations) {
  const auto fr1 = CameraPreset("tum_fr1");
  ASSERT_NE(fr1, nullptr);
  EXPECT_EQ(fr1->model_name(), "radtan");
  EXPECT_EQ(fr1->intrinsics().fx, 517.3);
  EXPECT_EQ(fr1->intrinsics().cy, 255.3);
  EXPECT_EQ(fr1->distortion(), (std::vector<double>{0.2624, -0.9531, -0.0054, 0.0026, 1.1633}));
  const auto fr2 = CameraPreset("tum_fr2");
  ASSERT_NE(fr2, nullptr);
  EXPECT_EQ(fr2->intrinsics().fy, 521.0);
  EXPECT_EQ(fr2->distortion()[4], 0.9172);
  const auto fr3 = CameraPreset("tum_fr3");
  ASSERT_NE(fr3, nullptr);
  EXPECT_EQ(fr3->model_name(), "pinhole");
  EXPECT_EQ(fr3->intrinsics().fx, 535.4);
  EXPECT_EQ(fr3->intrinsics().width, 640);
  EXPECT_EQ(fr3->intrinsics().height, 480);
  EXPECT_EQ(CameraPreset("tum_fr4"), nullptr);
  EXPECT_EQ(CameraPresetNames(), (std::vector<std::string>{"tum_fr1", "tum_fr2", "tum_fr3"}));
}

TEST(CameraYamlTest, UnknownPresetListsTheValidOnes) {
  try {
    CameraFromPresetOrFile("tum_fr9");
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("tum_fr9"), std::string::npos) << message;
    EXPECT_NE(message.find("tum_fr1, tum_fr2, tum_fr3"), std::string::npos) << message;
  }
}

TEST(CameraYamlTest, RoundTrip) {
  std::vector<std::unique_ptr<CameraModel>> cameras;
  for (const std::string& name : CameraPresetNames()) cameras.push_back(CameraPreset(name));
  PinholeCamera k;
  k.width = 1280;
  k.height = 1024;
  k.fx = 446.91584;
  k.fy = 629.16300800000001;
  k.cx = 643.43216;
  k.cy = 503.29366399999999;
  cameras.push_back(MakeCameraModel("fov", k, {0.935964}));
  for (size_t i = 0; i < cameras.size(); ++i) {
    const std::string path = TempPath(std::to_string(i) + ".yaml");
    WriteCameraYaml(*cameras[i], path);
    const auto read = ReadCameraYaml(path);
    ExpectSameCamera(*cameras[i], *read);
    ExpectSameCamera(*cameras[i], *CameraFromPresetOrFile(path));
  }
}

TEST(CameraYamlTest, ReadsAValidFileWithAndWithoutTheYamlHeader) {
  const auto camera = ReadCameraYaml(WriteFile("with.yaml", kValid));
  ExpectSameCamera(*camera, *CameraPreset("tum_fr1"));
  const std::string without = std::string(kValid).substr(std::string("%YAML:1.0\n---\n").size());
  ExpectSameCamera(*ReadCameraYaml(WriteFile("without.yaml", without)), *camera);
  // Integers are accepted for real-valued keys; [] for a pinhole.
  const auto pinhole = ReadCameraYaml(WriteFile(
      "pinhole.yaml",
      "model: pinhole\nwidth: 64\nheight: 48\nfx: 50\nfy: 50\ncx: 32\ncy: 24\ndistortion: []\n"));
  EXPECT_EQ(pinhole->model_name(), "pinhole");
  EXPECT_EQ(pinhole->intrinsics().fx, 50.0);
}

// Each malformed file gives an error naming the file and the key.
TEST(CameraYamlTest, MalformedFilesNameTheFileAndTheKey) {
  struct Case {
    std::string name;
    std::string from;  // replaced in kValid
    std::string to;
    std::string key;  // must appear in the message
  };
  const std::vector<Case> cases = {
      {"missing_key", "fx: 517.3\n", "", "'fx'"},
      {"missing_distortion", "distortion: [0.2624, -0.9531, -0.0054, 0.0026, 1.1633]\n", "",
       "'distortion'"},
      {"wrong_type_string", "fy: 516.5", "fy: big", "'fy'"},
      {"wrong_type_real_for_int", "width: 640", "width: 640.5", "'width'"},
      {"wrong_type_list", "cx: 318.6", "cx: [1, 2]", "'cx'"},
      {"unknown_model", "model: radtan", "model: kannala_brandt", "'model'"},
      {"too_few_distortion", ", 1.1633]", "]", "'distortion'"},
      {"distortion_not_a_list", "[0.2624, -0.9531, -0.0054, 0.0026, 1.1633]", "0.26",
       "'distortion'"},
      {"distortion_element", "-0.9531", "x", "'distortion'"},
      {"zero_focal", "fx: 517.3", "fx: 0", "'fx'"},
      {"negative_focal", "fy: 516.5", "fy: -516.5", "'fy'"},
      {"zero_height", "height: 480", "height: 0", "'height'"},
      {"unknown_key", "cy: 255.3\n", "cy: 255.3\nskew: 0\n", "'skew'"},
      {"duplicate_key", "cy: 255.3\n", "cy: 255.3\ncx: 1\n", "'cx'"},
      {"fov_w_out_of_range", "model: radtan", "model: fov", "'distortion'"},
  };
  for (const Case& c : cases) {
    std::string content = kValid;
    const size_t at = content.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.name;
    content.replace(at, c.from.size(), c.to);
    if (c.name == "fov_w_out_of_range") {
      content.replace(content.find("[0.2624"), std::string::npos, "[3.5]\n");
    }
    const std::string path = WriteFile(c.name + ".yaml", content);
    const std::string message = ReadError(path);
    EXPECT_NE(message.find(path), std::string::npos) << c.name << ": " << message;
    EXPECT_NE(message.find(c.key), std::string::npos) << c.name << ": " << message;
  }
}

TEST(CameraYamlTest, SyntaxErrorNamesTheFileAndLine) {
  std::string content = kValid;
  content.replace(content.find("1.1633]"), 7, "1.1633");  // unterminated list on line 10
  const std::string path = WriteFile("syntax.yaml", content);
  const std::string message = ReadError(path);
  EXPECT_NE(message.find(path + ":"), std::string::npos) << message;
  EXPECT_NE(message.find("syntax"), std::string::npos) << message;
}

TEST(CameraYamlTest, MissingFileNamesTheFile) {
  const std::string path = TempPath("does_not_exist.yaml");
  const std::string message = ReadError(path);
  EXPECT_NE(message.find(path), std::string::npos) << message;
}

}  // namespace
}  // namespace pldvo
