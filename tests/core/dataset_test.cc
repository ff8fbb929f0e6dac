// Every reader on tiny fixtures written into a temporary folder by the test itself.
#include "core/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zip.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>

#include "core/camera_model.h"
#include "core/camera_yaml.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

// A deterministic 8-bit test image; `seed` shifts the pattern so frames differ.
cv::Mat Pattern(int width, int height, int seed) {
  cv::Mat image(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) image.at<uint8_t>(y, x) = (7 * x + 13 * y + 31 * seed) % 256;
  }
  return image;
}

// The message of the std::exception `f` throws, or "" if it does not throw.
std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

class DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("pldvo_dataset_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string Path(const std::string& relative) const { return (root_ / relative).string(); }
  std::string Write(const std::string& relative, const std::string& text) const {
    fs::create_directories((root_ / relative).parent_path());
    std::ofstream(Path(relative)) << text;
    return Path(relative);
  }
  void WriteImage(const std::string& relative, const cv::Mat& image) const {
    fs::create_directories((root_ / relative).parent_path());
    ASSERT_TRUE(cv::imwrite(Path(relative), image));
  }
  void WritePinholeYaml(const std::string& relative, int width, int height) const {
    fs::create_directories((root_ / relative).parent_path());
    PinholeCamera pinhole{width, height, 50.0, 51.0, (width - 1) / 2.0, (height - 1) / 2.0};
    WriteCameraYaml(*MakeCameraModel("pinhole", pinhole, {}), Path(relative));
  }

  // TUM layout: 3 frames 40x30 at 30 Hz, depth.txt, groundtruth.txt at 100 Hz.
  void MakeTum() const {
    std::string rgb = "# color images\n# timestamp filename\n";
    std::string depth = "# depth maps\n";
    for (int i = 0; i < 3; ++i) {
      const std::string t = std::to_string(10.0 + i / 30.0);
      rgb += t + " rgb/" + std::to_string(i) + ".png\n";
      WriteImage("tum/rgb/" + std::to_string(i) + ".png", Pattern(40, 30, i));
    }
    // Depth of frames 0 and 1 within 0.02 s, of frame 2 0.025 s off (not associated).
    depth += "10.005 depth/0.png\n10.043 depth/1.png\n" + std::to_string(10.0 + 2 / 30.0 + 0.025) +
             " depth/2.png\n";
    Write("tum/rgb.txt", rgb);
    Write("tum/depth.txt", depth);
    std::string gt = "# timestamp tx ty tz qx qy qz qw\n";
    for (int i = 0; i < 10; ++i) {
      gt += std::to_string(10.0 + 0.01 * i) + " " + std::to_string(0.1 * i) + " 0 0 0 0 0 1\n";
    }
    Write("tum/groundtruth.txt", gt);
    WritePinholeYaml("tum/camera.yaml", 40, 30);
  }

  fs::path root_;
};

// ---------------------------------------------------------------- TUM RGB-D

TEST_F(DatasetTest, TumOpensAssociatesAndLoads) {
  MakeTum();
  const auto dataset = OpenDataset(Path("tum"));
  EXPECT_EQ(dataset->format(), "tum");
  ASSERT_EQ(dataset->size(), 3);
  EXPECT_NEAR(dataset->timestamp(1), 10.0 + 1 / 30.0, 1e-6);
  EXPECT_EQ(dataset->camera().width, 40);
  EXPECT_EQ(dataset->camera().fx, 50.0);
  ASSERT_NE(dataset->ground_truth(), nullptr);
  EXPECT_EQ(dataset->ground_truth()->size(), 10u);
  for (int i = 0; i < 3; ++i) {
    const Frame frame = dataset->Load(i);
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.image.type(), CV_32F);
    cv::Mat expected;
    Pattern(40, 30, i).convertTo(expected, CV_32F);
    // A pinhole camera: the image is the file's, exactly.
    EXPECT_EQ(cv::norm(frame.image, expected, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(frame.path, Path("tum/rgb/" + std::to_string(i) + ".png"));
  }
  EXPECT_EQ(dataset->Load(0).depth_path, Path("tum/depth/0.png"));
  EXPECT_EQ(dataset->Load(1).depth_path, Path("tum/depth/1.png"));
  EXPECT_EQ(dataset->Load(2).depth_path, "");
  EXPECT_THROW(dataset->Load(3), std::out_of_range);
}

TEST_F(DatasetTest, TumColourImageIsConvertedToGray) {
  MakeTum();
  cv::Mat colour(30, 40, CV_8UC3, cv::Scalar(10, 100, 200));  // B G R
  WriteImage("tum/rgb/0.png", colour);
  const Frame frame = OpenDataset(Path("tum"))->Load(0);
  ASSERT_EQ(frame.image.type(), CV_32F);
  // The decoder's own gray conversion (libpng's weights give 119 here, cvtColor's 120): the
  // reader must use it rather than, e.g., the first channel (10).
  const cv::Mat gray = cv::imread(Path("tum/rgb/0.png"), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(frame.image.at<float>(5, 5), gray.at<uint8_t>(5, 5));
  EXPECT_NEAR(frame.image.at<float>(5, 5), 120.0f, 2.0f);
}

TEST_F(DatasetTest, TumDistortedCameraIsUndistorted) {
  MakeTum();
  PinholeCamera pinhole{40, 30, 50.0, 50.0, 19.5, 14.5};
  const auto model = MakeCameraModel("radtan", pinhole, {-0.2, 0.05, 0.001, -0.001, 0.0});
  WriteCameraYaml(*model, Path("tum/camera.yaml"));
  const auto dataset = OpenDataset(Path("tum"));
  const Undistorter undistorter(*model);
  EXPECT_EQ(dataset->camera().fx, undistorter.output_camera().fx);
  cv::Mat raw;
  Pattern(40, 30, 1).convertTo(raw, CV_32F);
  EXPECT_EQ(cv::norm(dataset->Load(1).image, undistorter.Undistort(raw), cv::NORM_INF), 0.0);
}

TEST_F(DatasetTest, TumDepthIsReadInMetresAndUndistortedWithoutMixingSurfaces) {
  MakeTum();
  // Frame 0: a depth step (1 m left, 2 m right, x 5000 as in TUM) and a hole without depth.
  cv::Mat raw(30, 40, CV_16UC1);
  for (int y = 0; y < raw.rows; ++y) {
    for (int x = 0; x < raw.cols; ++x) raw.at<uint16_t>(y, x) = x < 20 ? 5000 : 10000;
  }
  raw(cv::Rect(5, 5, 4, 4)).setTo(0);
  WriteImage("tum/depth/0.png", raw);
  cv::Mat metres;
  raw.convertTo(metres, CV_32F, 1.0 / 5000.0);
  {
    const auto dataset = OpenDataset(Path("tum"));
    const cv::Mat depth = dataset->LoadDepth(0);
    ASSERT_EQ(depth.type(), CV_32F);
    EXPECT_EQ(cv::norm(depth, metres, cv::NORM_INF), 0.0);
    EXPECT_TRUE(dataset->LoadDepth(2).empty());  // no depth image associated with frame 2
    // Listed but missing (frame 1), and not 16-bit: errors naming the file.
    EXPECT_THAT(ErrorOf([&] { dataset->LoadDepth(1); }), HasSubstr(Path("tum/depth/1.png")));
    WriteImage("tum/depth/1.png", Pattern(40, 30, 0));
    EXPECT_THAT(ErrorOf([&] { dataset->LoadDepth(1); }),
                AllOf(HasSubstr(Path("tum/depth/1.png")), HasSubstr("16-bit")));
  }
  // A distorted camera: the depth goes through the image's undistortion with nearest-neighbour
  // sampling, so every output value is one of the input's (no depth between the two surfaces).
  PinholeCamera pinhole{40, 30, 50.0, 50.0, 19.5, 14.5};
  const auto model = MakeCameraModel("radtan", pinhole, {-0.2, 0.05, 0.001, -0.001, 0.0});
  WriteCameraYaml(*model, Path("tum/camera.yaml"));
  const cv::Mat depth = OpenDataset(Path("tum"))->LoadDepth(0);
  EXPECT_EQ(cv::norm(depth, Undistorter(*model).UndistortNearest(metres), cv::NORM_INF), 0.0);
  int ones = 0, twos = 0;
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float d = depth.at<float>(y, x);
      ASSERT_TRUE(d == 0.f || d == 1.f || d == 2.f) << d << " at " << x << ", " << y;
      ones += d == 1.f;
      twos += d == 2.f;
    }
  }
  EXPECT_GT(ones, 200);
  EXPECT_GT(twos, 200);
}

TEST_F(DatasetTest, TumCameraOptionOverridesTheFolder) {
  MakeTum();
  fs::remove(Path("tum/camera.yaml"));
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }),
              AllOf(HasSubstr(Path("tum")), HasSubstr("camera")));
  // Another calibration file given through the options.
  WritePinholeYaml("elsewhere/cam.yaml", 40, 30);
  DatasetOptions options;
  options.camera = Path("elsewhere/cam.yaml");
  EXPECT_EQ(OpenDataset(Path("tum"), options)->camera().fy, 51.0);
  // A preset: TUM fr3 is a 640x480 pinhole, so the 40x30 images are the wrong size.
  options.camera = "tum_fr3";
  const auto dataset = OpenDataset(Path("tum"), options);
  EXPECT_EQ(dataset->camera().width, 640);
  EXPECT_THAT(ErrorOf([&] { dataset->Load(0); }),
              AllOf(HasSubstr(Path("tum/rgb/0.png")), HasSubstr("40x30"), HasSubstr("640x480")));
}

TEST_F(DatasetTest, TumPresetFromFreiburgFolderName) {
  // A TUM RGB-D folder without camera.yaml: the preset its name gives (fr3: 640x480 pinhole).
  Write("rgbd_dataset_freiburg3_long_office/rgb.txt", "1.0 rgb/0.png\n");
  WriteImage("rgbd_dataset_freiburg3_long_office/rgb/0.png", Pattern(640, 480, 0));
  const auto dataset = OpenDataset(Path("rgbd_dataset_freiburg3_long_office/"));
  EXPECT_DOUBLE_EQ(dataset->camera().fx, 535.4);
  EXPECT_EQ(dataset->Load(0).image.cols, 640);
}

TEST_F(DatasetTest, TumMissingImageNamesTheFile) {
  MakeTum();
  fs::remove(Path("tum/rgb/1.png"));
  const auto dataset = OpenDataset(Path("tum"));
  EXPECT_THAT(ErrorOf([&] { dataset->Load(1); }), HasSubstr(Path("tum/rgb/1.png")));
  Write("tum/rgb/1.png", "not a png");
  EXPECT_THAT(ErrorOf([&] { dataset->Load(1); }),
              AllOf(HasSubstr(Path("tum/rgb/1.png")), HasSubstr("cannot decode")));
}

TEST_F(DatasetTest, TumWrongImageSizeNamesTheFile) {
  MakeTum();
  WriteImage("tum/rgb/2.png", Pattern(41, 30, 2));
  const auto dataset = OpenDataset(Path("tum"));
  EXPECT_THAT(ErrorOf([&] { dataset->Load(2); }),
              AllOf(HasSubstr(Path("tum/rgb/2.png")), HasSubstr("41x30")));
}

TEST_F(DatasetTest, TumBadLineNamesFileAndLine) {
  MakeTum();
  Write("tum/rgb.txt", "# c\n10.0 rgb/0.png\n10.1\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }),
              HasSubstr(Path("tum/rgb.txt") + ":3: expected 2 fields"));
  Write("tum/rgb.txt", "10.0 rgb/0.png\nten rgb/1.png\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }),
              HasSubstr(Path("tum/rgb.txt") + ":2: 'ten' is not a number"));
}

TEST_F(DatasetTest, TumNonMonotonicTimestampsNameFileAndLine) {
  MakeTum();
  Write("tum/rgb.txt", "10.0 rgb/0.png\n10.1 rgb/1.png\n10.05 rgb/2.png\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }),
              HasSubstr(Path("tum/rgb.txt") + ":3: timestamp 10.05 does not increase"));
  MakeTum();
  Write("tum/groundtruth.txt", "1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }),
              HasSubstr(Path("tum/groundtruth.txt") + ":2:"));
}

TEST_F(DatasetTest, TumUnknownCameraModelIsAnError) {
  MakeTum();
  Write("tum/camera.yaml",
        "%YAML:1.0\n---\nmodel: kannala_brandt\nwidth: 40\nheight: 30\nfx: 50.0\nfy: 50.0\n"
        "cx: 19.5\ncy: 14.5\ndistortion: [0.1, 0.2, 0.3, 0.4]\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }), HasSubstr("kannala_brandt"));
}

TEST_F(DatasetTest, TumEmptySequenceIsAnError) {
  MakeTum();
  Write("tum/rgb.txt", "# nothing\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum")); }),
              HasSubstr(Path("tum/rgb.txt") + ": lists no images"));
}

// ---------------------------------------------------------------- TUM monoVO

class MonoVoTest : public DatasetTest {
 protected:
  static constexpr int kWidth = 32, kHeight = 24;

  // images/ (or images.zip), times.txt, a pinhole camera.txt (FOV with w = 0), pcalib.txt
  // G^-1(i) = 7 + 1000 (i / 255)^2 and a 16-bit vignette falling from 60000 to 30000 with x.
  void MakeMono(bool zip) const {
    std::string times;
    for (int i = 0; i < 4; ++i) {
      times += std::to_string(i) + " " + std::to_string(100.0 + 0.05 * i) + " " +
               std::to_string(10.0 + i) + "\n";
    }
    Write("mono/times.txt", times);
    Write("mono/camera.txt", "0.5 0.6 0.5 0.5 0\n32 24\n");
    std::string pcalib;
    for (int i = 0; i < 256; ++i)
      pcalib += std::to_string(7.0 + 1000.0 * (i / 255.0) * (i / 255.0)) + " ";
    Write("mono/pcalib.txt", pcalib + "\n");
    cv::Mat vignette(kHeight, kWidth, CV_16UC1);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x)
        vignette.at<uint16_t>(y, x) = 60000 - 30000 * x / (kWidth - 1);
    }
    WriteImage("mono/vignette.png", vignette);
    if (!zip) {
      for (int i = 0; i < 4; ++i) {
        char name[32];
        std::snprintf(name, sizeof(name), "mono/images/%05d.png", i);
        WriteImage(name, Pattern(kWidth, kHeight, i));
      }
      return;
    }
    // images.zip written with libzip; the encoded PNGs must outlive zip_close.
    std::vector<std::vector<uchar>> buffers(4);
    int error = 0;
    zip_t* archive = zip_open(Path("mono/images.zip").c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
    ASSERT_NE(archive, nullptr);
    for (int i = 3; i >= 0; --i) {  // out of order: the reader sorts by name
      ASSERT_TRUE(cv::imencode(".png", Pattern(kWidth, kHeight, i), buffers[i]));
      zip_source_t* source = zip_source_buffer(archive, buffers[i].data(), buffers[i].size(), 0);
      ASSERT_NE(source, nullptr);
      char name[32];
      std::snprintf(name, sizeof(name), "%05d.png", i);
      ASSERT_GE(zip_file_add(archive, name, source, ZIP_FL_OVERWRITE), 0);
    }
    ASSERT_EQ(zip_close(archive), 0);
  }

  // The expected corrected intensity of raw value `raw` at column x (G^-1 rescaled to 0..255).
  static float Expected(int raw, int x) {
    const double g = 1000.0 * (raw / 255.0) * (raw / 255.0) * 255.0 / 1000.0;
    const double vignette = (60000 - 30000 * x / (kWidth - 1)) / 60000.0;
    return static_cast<float>(g / vignette);
  }

  // The exposure factor t_ref / t_i of frame i: exposures 10, 11, 12, 13 ms, t_ref their median
  // 11.5 ms.
  static double ExposureScale(int i) { return 11.5 / (10.0 + i); }

  void ExpectPhotometricallyCorrected(const Dataset& dataset) const {
    ASSERT_EQ(dataset.size(), 4);
    EXPECT_EQ(dataset.format(), "tum_mono");
    EXPECT_DOUBLE_EQ(dataset.timestamp(2), 100.1);
    // Relative calibration (DSO): fx = 0.5 * 32, cx = 0.5 * 32 - 0.5.
    EXPECT_DOUBLE_EQ(dataset.camera().fx, 16.0);
    EXPECT_DOUBLE_EQ(dataset.camera().fy, 14.4);
    EXPECT_DOUBLE_EQ(dataset.camera().cx, 15.5);
    EXPECT_DOUBLE_EQ(dataset.camera().cy, 11.5);
    for (int i = 0; i < 4; ++i) {
      const Frame frame = dataset.Load(i);
      EXPECT_DOUBLE_EQ(frame.exposure_ms, 10.0 + i);
      const cv::Mat raw = Pattern(kWidth, kHeight, i);
      for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
          // float arithmetic on values up to 510: relative error below 1e-6.
          ASSERT_NEAR(frame.image.at<float>(y, x),
                      ExposureScale(i) * Expected(raw.at<uint8_t>(y, x), x), 1e-3)
              << "frame " << i << " pixel " << x << "," << y;
        }
      }
    }
  }
};

TEST_F(MonoVoTest, FolderImagesArePhotometricallyCorrected) {
  MakeMono(/*zip=*/false);
  const auto dataset = OpenDataset(Path("mono"));
  ExpectPhotometricallyCorrected(*dataset);
  EXPECT_EQ(dataset->Load(0).path, Path("mono/images/00000.png"));
}

TEST_F(MonoVoTest, ExposureIsNormalisedOnlyOnLinearIntensities) {
  MakeMono(/*zip=*/false);
  const cv::Mat raw = Pattern(kWidth, kHeight, 3);
  // Switched off: G^-1(I) / V alone.
  DatasetOptions options;
  options.normalize_exposure = false;
  const Frame plain = OpenDataset(Path("mono"), options)->Load(3);
  EXPECT_NEAR(plain.image.at<float>(5, 7), Expected(raw.at<uint8_t>(5, 7), 7), 1e-3);
  // Without pcalib.txt the intensities are not linear in the exposure: no scaling either.
  fs::remove(Path("mono/pcalib.txt"));
  const Frame no_response = OpenDataset(Path("mono"))->Load(3);
  const double vignette = (60000 - 30000 * 7 / (kWidth - 1)) / 60000.0;
  EXPECT_NEAR(no_response.image.at<float>(5, 7), raw.at<uint8_t>(5, 7) / vignette, 1e-3);
  // Without exposure times (two-column times.txt) nothing is scaled.
  MakeMono(/*zip=*/false);
  Write("mono/times.txt", "0 100.0\n1 100.05\n2 100.1\n3 100.15\n");
  const Frame no_exposure = OpenDataset(Path("mono"))->Load(3);
  EXPECT_DOUBLE_EQ(no_exposure.exposure_ms, 0.0);
  EXPECT_NEAR(no_exposure.image.at<float>(5, 7), Expected(raw.at<uint8_t>(5, 7), 7), 1e-3);
}

TEST_F(MonoVoTest, ZipImagesAreReadThroughLibzip) {
  MakeMono(/*zip=*/true);
  const auto dataset = OpenDataset(Path("mono"));
  ExpectPhotometricallyCorrected(*dataset);
  EXPECT_EQ(dataset->Load(3).path, Path("mono/images.zip") + ":00003.png");
}

TEST_F(MonoVoTest, FovCropGivesAnOutputCameraInsideTheImage) {
  MakeMono(/*zip=*/false);
  Write("mono/camera.txt", "FOV 0.6 0.8 0.5 0.5 0.9\n32 24\ncrop\n24 18\n");
  // A uniform frame: after correction and remap, a zero pixel could only be one without source.
  WriteImage("mono/images/00001.png", cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(100)));
  const auto dataset = OpenDataset(Path("mono"));
  const PinholeCamera& output = dataset->camera();
  EXPECT_EQ(output.width, 24);
  EXPECT_EQ(output.height, 18);
  const Frame frame = dataset->Load(1);
  EXPECT_EQ(frame.image.cols, 24);
  EXPECT_EQ(frame.image.rows, 18);
  // Every output border pixel has a source inside the input image ("crop"), and the crop is
  // tight: 0.5% larger on all sides and some border pixel falls outside.
  const auto model = MakeCameraModel("fov", {32, 24, 0.6 * 32, 0.8 * 24, 15.5, 11.5}, {0.9});
  auto all_inside = [&](const PinholeCamera& camera) {
    for (int u = 0; u < camera.width; ++u) {
      for (int v : {0, camera.height - 1}) {
        const Eigen::Vector2d p = model->Project(camera.Unproject(Eigen::Vector2d(u, v)));
        if (!model->intrinsics().IsInside(p, 0.0)) return false;
      }
    }
    for (int v = 0; v < camera.height; ++v) {
      for (int u : {0, camera.width - 1}) {
        const Eigen::Vector2d p = model->Project(camera.Unproject(Eigen::Vector2d(u, v)));
        if (!model->intrinsics().IsInside(p, 0.0)) return false;
      }
    }
    return true;
  };
  EXPECT_TRUE(all_inside(output));
  PinholeCamera wider = output;
  wider.fx /= 1.02;
  wider.fy /= 1.02;
  wider.cx = (output.cx - (output.width - 1) / 2.0) / 1.02 + (output.width - 1) / 2.0;
  wider.cy = (output.cy - (output.height - 1) / 2.0) / 1.02 + (output.height - 1) / 2.0;
  EXPECT_FALSE(all_inside(wider));
  // No pixel of the crop is left without a source.
  double min_value = 0.0;
  cv::minMaxLoc(frame.image, &min_value);
  EXPECT_GT(min_value, 0.0);
}

TEST_F(MonoVoTest, FovFullKeepsEverySourcePixel) {
  MakeMono(/*zip=*/false);
  Write("mono/camera.txt", "0.6 0.8 0.5 0.5 0.9\n32 24\nfull\n24 18\n");
  const auto dataset = OpenDataset(Path("mono"));
  const PinholeCamera& output = dataset->camera();
  ASSERT_EQ(output.width, 24);
  // Every input border pixel lands inside the output image; the extreme ones on its border.
  const auto model = MakeCameraModel("fov", {32, 24, 0.6 * 32, 0.8 * 24, 15.5, 11.5}, {0.9});
  double min_u = 1e9, max_u = -1e9;
  for (int v = 0; v < 24; ++v) {
    for (int u : {0, 31}) {
      const Eigen::Vector2d p = output.Project(model->Unproject(Eigen::Vector2d(u, v)));
      min_u = std::min(min_u, p.x());
      max_u = std::max(max_u, p.x());
    }
  }
  // 1e-9 px: the bounding box is computed from these same border pixels.
  EXPECT_NEAR(min_u, 0.0, 1e-9);
  EXPECT_NEAR(max_u, output.width - 1.0, 1e-9);
  EXPECT_EQ(dataset->Load(0).image.rows, 18);
}

TEST_F(MonoVoTest, UnsupportedCameraModelNamesFileAndLine) {
  MakeMono(/*zip=*/false);
  Write("mono/camera.txt", "KannalaBrandt 0.5 0.6 0.5 0.5 0.1 0.2 0.3 0.4\n32 24\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("mono")); }),
              AllOf(HasSubstr(Path("mono/camera.txt") + ":1:"), HasSubstr("kannalabrandt")));
  Write("mono/camera.txt", "0.5 0.6 0.5 0.5 0\n32\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("mono")); }),
              HasSubstr(Path("mono/camera.txt") + ":2:"));
}

TEST_F(MonoVoTest, TimesErrorsNameFileAndLine) {
  MakeMono(/*zip=*/false);
  Write("mono/times.txt", "0 100.0 10\n1 100.05 10\n2 100.02 10\n3 100.2 10\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("mono")); }),
              HasSubstr(Path("mono/times.txt") + ":3: timestamp 100.02 does not increase"));
  Write("mono/times.txt", "0 100.0 10\n1 100.05 10\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("mono")); }),
              AllOf(HasSubstr(Path("mono/times.txt")), HasSubstr("2 timestamps for 4 images")));
}

TEST_F(MonoVoTest, BadPhotometricCalibrationIsAnError) {
  MakeMono(/*zip=*/false);
  Write("mono/pcalib.txt", "1 2 3\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("mono")); }),
              AllOf(HasSubstr(Path("mono/pcalib.txt")), HasSubstr("256")));
  MakeMono(/*zip=*/false);
  WriteImage("mono/vignette.png", cv::Mat(10, 10, CV_16UC1, cv::Scalar(100)));
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("mono")); }),
              AllOf(HasSubstr(Path("mono/vignette.png")), HasSubstr("10x10")));
}

TEST_F(MonoVoTest, WrongImageSizeNamesTheFile) {
  MakeMono(/*zip=*/false);
  WriteImage("mono/images/00002.png", Pattern(30, 24, 2));
  const auto dataset = OpenDataset(Path("mono"));
  EXPECT_THAT(ErrorOf([&] { dataset->Load(2); }), HasSubstr(Path("mono/images/00002.png")));
}

// ---------------------------------------------------------------- EuRoC

class EurocTest : public DatasetTest {
 protected:
  // body_from_cam of the fixture: a rotation of 90 deg about z and a translation.
  static SE3 BodyFromCam() {
    return SE3(Eigen::Matrix3d(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
               Eigen::Vector3d(0.1, -0.2, 0.3));
  }

  void MakeEuroc() const {
    Write("euroc/mav0/cam0/sensor.yaml",
          "# General sensor definitions.\nsensor_type: camera\ncomment: VI-Sensor cam0\n\n"
          "# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n"
          "  data: [0.0, -1.0, 0.0, 0.1,\n         1.0, 0.0, 0.0, -0.2,\n"
          "         0.0, 0.0, 1.0, 0.3,\n         0.0, 0.0, 0.0, 1.0]\n\n"
          "rate_hz: 20\nresolution: [40, 30]\ncamera_model: pinhole\n"
          "intrinsics: [45.0, 46.0, 19.0, 15.0] #fu, fv, cu, cv\n"
          "distortion_model: radial-tangential\n"
          "distortion_coefficients: [-0.28, 0.07, 0.0002, 1.7e-05]\n");
    std::string list = "#timestamp [ns],filename\n";
    for (int i = 0; i < 3; ++i) {
      const std::string ns = std::to_string(1403636579763555584LL + 50000000LL * i);
      list += ns + "," + ns + ".png\n";
      WriteImage("euroc/mav0/cam0/data/" + ns + ".png", Pattern(40, 30, i));
    }
    Write("euroc/mav0/cam0/data.csv", list);
    std::string gt =
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
        "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y, v_RS_R_z, b_w_RS_S_x, b_w_RS_S_y, b_w_RS_S_z, "
        "b_a_RS_S_x, b_a_RS_S_y, b_a_RS_S_z\n";
    for (int i = 0; i < 5; ++i) {
      // q_RS = rotation of 60 deg about x: (w, x) = (cos 30, sin 30).
      gt += std::to_string(1403636579763555584LL + 5000000LL * i) + "," + std::to_string(i) +
            ",2,3,0.86602540378443865,0.5,0,0,0,0,0,0,0,0,0,0,0\n";
    }
    Write("euroc/mav0/state_groundtruth_estimate0/data.csv", gt);
  }
};

TEST_F(EurocTest, OpensWithGroundTruthInTheCameraFrame) {
  MakeEuroc();
  const auto dataset = OpenDataset(Path("euroc"));
  EXPECT_EQ(dataset->format(), "euroc");
  ASSERT_EQ(dataset->size(), 3);
  // 1403636579.763555584 s: a double keeps ~0.2 us at this magnitude.
  EXPECT_NEAR(dataset->timestamp(0), 1403636579.763555584, 1e-6);
  EXPECT_NEAR(dataset->timestamp(2) - dataset->timestamp(0), 0.1, 1e-6);
  // The radtan camera is undistorted like any other model (core/camera_model.h).
  const auto model = MakeCameraModel("radtan", {40, 30, 45.0, 46.0, 19.0, 15.0},
                                     {-0.28, 0.07, 0.0002, 1.7e-05, 0.0});
  const Undistorter undistorter(*model);
  EXPECT_EQ(dataset->camera().fx, undistorter.output_camera().fx);
  cv::Mat raw;
  Pattern(40, 30, 2).convertTo(raw, CV_32F);
  EXPECT_EQ(cv::norm(dataset->Load(2).image, undistorter.Undistort(raw), cv::NORM_INF), 0.0);

  const Trajectory* gt = dataset->ground_truth();
  ASSERT_NE(gt, nullptr);
  ASSERT_EQ(gt->size(), 5u);
  const SE3 world_from_body(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 3, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(4, 2, 3));
  const SE3 expected = world_from_body * BodyFromCam();
  // Quaternion and T_BS given with 17 digits: agreement to rounding.
  EXPECT_LT(((*gt)[4].world_from_cam.matrix() - expected.matrix()).norm(), 1e-12);

  // The mav0 folder itself opens too.
  EXPECT_EQ(OpenDataset(Path("euroc/mav0"))->size(), 3);
}

TEST_F(EurocTest, ErrorsNameFileAndLine) {
  MakeEuroc();
  Write("euroc/mav0/cam0/data.csv", "#timestamp [ns],filename\n20,a.png\n10,b.png\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("euroc")); }),
              HasSubstr(Path("euroc/mav0/cam0/data.csv") + ":3: timestamp"));
  MakeEuroc();
  Write("euroc/mav0/cam0/data.csv", "#timestamp [ns],filename\n20,a.png,extra\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("euroc")); }),
              HasSubstr(Path("euroc/mav0/cam0/data.csv") + ":2: expected 2 fields"));
  MakeEuroc();
  std::string yaml;
  {
    std::ifstream in(Path("euroc/mav0/cam0/sensor.yaml"));
    yaml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  yaml.replace(yaml.find("radial-tangential"), 17, "equidistant");
  Write("euroc/mav0/cam0/sensor.yaml", yaml);
  EXPECT_THAT(
      ErrorOf([&] { OpenDataset(Path("euroc")); }),
      AllOf(HasSubstr(Path("euroc/mav0/cam0/sensor.yaml") + ":18:"), HasSubstr("equidistant")));
}

// ---------------------------------------------------------------- KITTI

class KittiTest : public DatasetTest {
 protected:
  void MakeKitti() const {
    Write("kitti/sequences/07/calib.txt",
          "P0: 7.070912e+02 0.000000e+00 6.018873e+02 0.000000e+00 0.000000e+00 7.070912e+02 "
          "1.831104e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n"
          "P1: 7.070912e+02 0.000000e+00 6.018873e+02 -3.798145e+02 0.000000e+00 7.070912e+02 "
          "1.831104e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n");
    Write("kitti/sequences/07/times.txt", "0.000000e+00\n1.036000e-01\n2.073000e-01\n");
    std::string poses;
    for (int i = 0; i < 3; ++i) {
      WriteImage("kitti/sequences/07/image_0/00000" + std::to_string(i) + ".png",
                 Pattern(40, 30, i));
      poses +=
          "1 0 0 " + std::to_string(0.01 * i) + " 0 1 0 0 0 0 1 " + std::to_string(0.8 * i) + "\n";
    }
    Write("kitti/poses/07.txt", poses);
  }
};

TEST_F(KittiTest, OpensWithCalibrationAndPosesNearby) {
  MakeKitti();
  const auto dataset = OpenDataset(Path("kitti/sequences/07"));
  EXPECT_EQ(dataset->format(), "kitti");
  ASSERT_EQ(dataset->size(), 3);
  EXPECT_DOUBLE_EQ(dataset->timestamp(1), 0.1036);
  EXPECT_DOUBLE_EQ(dataset->camera().fx, 707.0912);
  EXPECT_DOUBLE_EQ(dataset->camera().cy, 183.1104);
  EXPECT_EQ(dataset->camera().width, 40);
  const Trajectory* gt = dataset->ground_truth();
  ASSERT_NE(gt, nullptr);
  ASSERT_EQ(gt->size(), 3u);
  EXPECT_DOUBLE_EQ((*gt)[2].timestamp, 0.2073);
  EXPECT_EQ((*gt)[2].world_from_cam.translation(), Eigen::Vector3d(0.02, 0, 1.6));
  cv::Mat expected;
  Pattern(40, 30, 1).convertTo(expected, CV_32F);
  EXPECT_EQ(cv::norm(dataset->Load(1).image, expected, cv::NORM_INF), 0.0);
}

TEST_F(KittiTest, PosesErrorsNameFileAndLine) {
  MakeKitti();
  Write("kitti/poses/07.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("kitti/sequences/07")); }),
              HasSubstr(Path("kitti/poses/07.txt") + ":2: rotation is not orthonormal"));
  Write("kitti/poses/07.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("kitti/sequences/07")); }),
              HasSubstr("1 poses for 3 frames"));
  // Given explicitly through the options.
  Write("elsewhere.txt",
        "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n1 0 0 0 0 1 0 0 0 0 1 2\n");
  DatasetOptions options;
  options.ground_truth = Path("elsewhere.txt");
  EXPECT_EQ(OpenDataset(Path("kitti/sequences/07"), options)->ground_truth()->size(), 3u);
}

TEST_F(KittiTest, MissingCalibrationLineIsAnError) {
  MakeKitti();
  Write("kitti/sequences/07/calib.txt", "P1: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("kitti/sequences/07")); }),
              HasSubstr(Path("kitti/sequences/07/calib.txt") + ": no 'P0:' line"));
  Write("kitti/sequences/07/calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("kitti/sequences/07")); }),
              HasSubstr(Path("kitti/sequences/07/calib.txt") + ":1:"));
}

// ---------------------------------------------------------------- detection

TEST_F(DatasetTest, DetectsEachFormat) {
  MakeTum();
  EXPECT_EQ(DetectDatasetFormat(Path("tum")), "tum");
  Write("mono/times.txt", "0 1.0\n");
  fs::create_directories(Path("mono/images"));
  EXPECT_EQ(DetectDatasetFormat(Path("mono")), "tum_mono");
  Write("euroc/mav0/cam0/data.csv", "");
  EXPECT_EQ(DetectDatasetFormat(Path("euroc")), "euroc");
  Write("kitti/calib.txt", "");
  Write("kitti/times.txt", "");
  fs::create_directories(Path("kitti/image_0"));
  EXPECT_EQ(DetectDatasetFormat(Path("kitti")), "kitti");
}

TEST_F(DatasetTest, UndetectableFolderSaysWhatWasLookedFor) {
  fs::create_directories(Path("empty"));
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("empty")); }),
              AllOf(HasSubstr(Path("empty")), HasSubstr("rgb.txt"), HasSubstr("mav0/cam0/data.csv"),
                    HasSubstr("image_0"), HasSubstr("images.zip")));
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("missing")); }), HasSubstr(Path("missing")));
}

TEST_F(DatasetTest, ForcedFormatIsUsedAndUnknownFormatRejected) {
  MakeTum();
  DatasetOptions options;
  options.format = "kitti";
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum"), options); }),
              HasSubstr(Path("tum/times.txt")));
  options.format = "rosbag";
  EXPECT_THAT(ErrorOf([&] { OpenDataset(Path("tum"), options); }), HasSubstr("rosbag"));
  options.format = "tum";
  EXPECT_EQ(OpenDataset(Path("tum"), options)->format(), "tum");
}

}  // namespace
}  // namespace pldvo
