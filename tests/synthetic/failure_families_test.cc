// The synthetic failure families of the point-to-line term (issue #41; docs/synthetic.md,
// "Failure families") on known photometry and geometry: contrast scales the deviation from
// mid-gray and brightness shifts the image before the noise, clipping at 0 and 255; the
// auto-exposure gain is a bounded, smooth walk that scales the image; the checkerboard's squares
// are where the room's planes predict them; the boxes' outlines are depth discontinuities; the
// handheld path rotates at TUM fr1/rpy's rates about all three axes, and with a pivot its turns
// carry the camera centre along. Small images (320x240,
// 160x120) and a few frames, rendered through the test render cache.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/synthetic/synthetic_sequence.h"
#include "tests/render_cache.h"
#include "tests/sanitizer_budget.h"

namespace pldvo::synthetic {
namespace {

using test::RenderFrameForTest;

SynthOptions SmallOptions(const std::string& preset, int frames, int width = 320,
                          int height = 240) {
  SynthOptions options;
  options.preset = preset;
  options.frames = frames;
  options.width = width;
  options.height = height;
  options.fx = options.fy = 525.0 * width / 640.0;  // the 640x480 field of view
  options.threads = 2;
  return options;
}

// Least-squares slope of y - 127.5 on x - 127.5 (through mid-gray) over the pixels where both
// images are unclipped, and the median absolute residual.
void FitAroundMidGray(const cv::Mat& x, const cv::Mat& y, double* slope, double* median_residual) {
  double sxy = 0.0, sxx = 0.0;
  std::vector<std::pair<double, double>> pairs;
  for (int r = 0; r < x.rows; ++r) {
    for (int c = 0; c < x.cols; ++c) {
      const int a = x.at<uint8_t>(r, c), b = y.at<uint8_t>(r, c);
      if (a <= 0 || a >= 255 || b <= 0 || b >= 255) continue;
      pairs.emplace_back(a - 127.5, b - 127.5);
      sxy += (a - 127.5) * (b - 127.5);
      sxx += (a - 127.5) * (a - 127.5);
    }
  }
  *slope = sxy / sxx;
  std::vector<double> residuals;
  for (const auto& [a, b] : pairs) residuals.push_back(std::abs(b - *slope * a));
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  *median_residual = residuals[residuals.size() / 2];
}

double MeanAbsDeviationFromMidGray(const cv::Mat& image) {
  double sum = 0.0;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) sum += std::abs(image.at<uint8_t>(r, c) - 127.5);
  }
  return sum / image.total();
}

// Contrast c: I_c - 127.5 = c (I_1 - 127.5) + (1 - c) n, n the shared sensor noise (sigma 1),
// so the fitted slope is c and the residual about |1 - c| gray levels plus rounding.
TEST(FailureFamiliesTest, ContrastScalesTheDeviationFromMidGray) {
  const SyntheticSequence plain = MakeSequence(SmallOptions("lowtex", 2));
  const cv::Mat reference = RenderFrameForTest(plain, 1).image;
  for (const double contrast : {0.5, 0.75, 1.25}) {
    SynthOptions options = SmallOptions("lowtex", 2);
    options.contrast = contrast;
    const SyntheticSequence sequence = MakeSequence(options);
    const cv::Mat image = RenderFrameForTest(sequence, 1).image;
    double slope, residual;
    FitAroundMidGray(reference, image, &slope, &residual);
    // The slope's error: the noise part (1 - c) n over a ~50 gray-level spread, well below 1%.
    EXPECT_NEAR(slope, contrast, 0.01) << "contrast " << contrast;
    EXPECT_LT(residual, 1.0) << "contrast " << contrast;
    if (contrast == 0.5) {
      // Halved deviation from mid-gray (no pixel clips at 1x or 0.5x in this frame).
      const double ratio =
          MeanAbsDeviationFromMidGray(image) / MeanAbsDeviationFromMidGray(reference);
      EXPECT_NEAR(ratio, 0.5, 0.02);
    }
    const Lighting lighting = LightingAt(sequence, 0.0);
    EXPECT_DOUBLE_EQ(lighting.gain, contrast);
    EXPECT_DOUBLE_EQ(lighting.bias, 127.5 * (1.0 - contrast));
    std::cout << "contrast " << contrast << ": slope " << slope << ", median residual " << residual
              << "\n";
  }
}

// Brightness b: I + 255 b before the noise; the shared noise makes the difference exact where
// neither image clips, and pixels pushed past 255 (or 0) read 255 (or 0), as on a camera.
TEST(FailureFamiliesTest, BrightnessShiftsTheImageAndClips) {
  const SyntheticSequence plain = MakeSequence(SmallOptions("lowtex", 2));
  const cv::Mat reference = RenderFrameForTest(plain, 1).image;
  for (const double brightness : {0.2, -0.2}) {
    SynthOptions options = SmallOptions("lowtex", 2);
    options.brightness = brightness;
    options.contrast = 1.25;  // also pushes the bright walls into saturation
    const SyntheticSequence sequence = MakeSequence(options);
    const cv::Mat image = RenderFrameForTest(sequence, 1).image;
    int exact = 0, compared = 0, clipped = 0, clipped_right = 0;
    for (int r = 0; r < image.rows; ++r) {
      for (int c = 0; c < image.cols; ++c) {
        const double predicted =
            1.25 * (reference.at<uint8_t>(r, c) - 127.5) + 127.5 + 255.0 * brightness;
        const int value = image.at<uint8_t>(r, c);
        if (predicted > 1.0 && predicted < 254.0) {
          // 1.25 n of the scaled noise against the reference's n: within 1 gray level nearly
          // always (|0.25 n| + rounding of both).
          ++compared;
          exact += std::abs(value - predicted) <= 1.5;
        } else if (predicted >= 257.0 || predicted <= -2.0) {
          ++clipped;
          clipped_right += value == (predicted > 0.0 ? 255 : 0);
        }
      }
    }
    EXPECT_GT(compared, static_cast<int>(image.total() / 4)) << brightness;
    EXPECT_GT(exact, 0.97 * compared) << brightness;
    EXPECT_GT(clipped, 0) << "no pixel saturates at brightness " << brightness;
    EXPECT_EQ(clipped_right, clipped) << brightness;
    std::cout << "brightness " << brightness << ": " << exact << " / " << compared
              << " within 1.5 gray levels, " << clipped << " clipped\n";
  }
}

// The auto-exposure gain: within 1 +- amplitude, swinging over the sequence, smooth (the
// smoothstep between knots every 2 s changes by at most 1.5 x 2 x 0.3 / 2 s = 0.45 per second,
// 0.015 per frame), and the image is the plain one times the gain.
TEST(FailureFamiliesTest, AutoExposureGainIsASmoothBoundedWalkThatScalesTheImage) {
  for (const int seed : {1, 2, 3}) {
    SynthOptions options = SmallOptions("autoexposure", 300, 160, 120);
    options.seed = seed;
    const SyntheticSequence sequence = MakeSequence(options);
    double lo = 10.0, hi = 0.0, max_step = 0.0, previous = 1.0;
    for (int i = 0; i < 300; ++i) {
      const double gain = LightingAt(sequence, i / options.fps).gain;
      lo = std::min(lo, gain);
      hi = std::max(hi, gain);
      if (i > 0) max_step = std::max(max_step, std::abs(gain - previous));
      previous = gain;
    }
    EXPECT_GE(lo, 0.7) << seed;
    EXPECT_LE(hi, 1.3) << seed;
    EXPECT_GT(hi - lo, 0.2) << "seed " << seed << " barely moves its exposure";
    EXPECT_LT(max_step, 0.0151) << seed;
    std::cout << "autoexposure seed " << seed << ": gain in [" << lo << ", " << hi
              << "], largest step per frame " << max_step << "\n";
  }
  // The frame of the 60 whose gain is farthest from 1 against the plain lowtex frame: the same
  // scene and path (photometry draws nothing of them), the image scaled by the gain.
  const SyntheticSequence exposed = MakeSequence(SmallOptions("autoexposure", 60));
  const SyntheticSequence plain = MakeSequence(SmallOptions("lowtex", 60));
  int farthest = 0;
  for (int i = 0; i < 60; ++i) {
    if (std::abs(LightingAt(exposed, i / 30.0).gain - 1.0) >
        std::abs(LightingAt(exposed, farthest / 30.0).gain - 1.0)) {
      farthest = i;
    }
  }
  ASSERT_TRUE(exposed.ground_truth[farthest].world_from_cam.translation().isApprox(
      plain.ground_truth[farthest].world_from_cam.translation()));
  const double gain = LightingAt(exposed, farthest / 30.0).gain;
  cv::Mat a = RenderFrameForTest(plain, farthest).image;
  cv::Mat b = RenderFrameForTest(exposed, farthest).image;
  // I_b = g L + n against I_a = L + n: the slope through 0 is g up to (1 - g) n / L, < 0.5%.
  double sab = 0.0, saa = 0.0;
  for (int r = 0; r < a.rows; ++r) {
    for (int c = 0; c < a.cols; ++c) {
      const double x = a.at<uint8_t>(r, c), y = b.at<uint8_t>(r, c);
      if (x <= 0 || x >= 255 || y <= 0 || y >= 255) continue;
      sab += x * y;
      saa += x * x;
    }
  }
  EXPECT_NEAR(sab / saa, gain, 0.005) << "frame " << farthest;
  std::cout << "autoexposure frame " << farthest << ": gain " << gain << ", image ratio "
            << sab / saa << "\n";
}

// The squares, predicted from the room's planes (walls and floor) and the square size alone
// (not through the scene): over pixels that see a room plane (rendered depth on it) at least 2 px
// from a predicted square boundary, the dark squares are dark and the light ones light. A
// prediction shifted by half a square agrees on about half of them.
TEST(FailureFamiliesTest, CheckerboardSquaresAppearWherePredicted) {
  const SyntheticSequence sequence = MakeSequence(SmallOptions("checkerboard", 60));
  const double size = sequence.options.checker_size;
  ASSERT_DOUBLE_EQ(size, 0.08);
  const PinholeCamera& camera = sequence.camera;
  const Eigen::Vector3d& room = sequence.scene.room_size();
  int agree = 0, checked = 0, shifted_agree = 0;
  for (const int index : {0, 20, 40}) {
    const SE3& world_from_cam = sequence.ground_truth[index].world_from_cam;
    const RenderedFrame frame = RenderFrameForTest(sequence, index);
    const Eigen::Matrix3d rotation = world_from_cam.rotation_matrix();
    const Eigen::Vector3d origin = world_from_cam.translation();
    // Predicted parity (1: dark) and z-depth of the nearest room plane at a pixel (the camera is
    // inside the room: the exit through the walls x = 0, X, y = 0, Y and the floor z = 0); -1
    // for the ceiling, which has no squares. Face coordinates as Scene::Albedo's: the other two
    // world coordinates, from the room's corner at the origin.
    auto predict = [&](double x, double y, double shift, double* depth) {
      const Eigen::Vector3d direction = rotation * camera.Unproject(Eigen::Vector2d(x, y));
      double best = 1e9;
      int axis = -1;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(direction[a]) < 1e-12) continue;
        const double t = ((direction[a] > 0.0 ? room[a] : 0.0) - origin[a]) / direction[a];
        if (t < best) best = t, axis = direction[a] > 0.0 && a == 2 ? -1 : a;
      }
      if (axis < 0) return -1;
      *depth = best;  // the ray has z = 1 in the camera frame
      const Eigen::Vector3d point = origin + best * direction;
      const long iu = static_cast<long>(std::floor(point[(axis + 1) % 3] / size + shift));
      const long iv = static_cast<long>(std::floor(point[(axis + 2) % 3] / size + shift));
      return static_cast<int>((iu + iv) & 1);
    };
    std::vector<int> dark, light;              // intensities by predicted parity
    std::vector<std::pair<int, int>> samples;  // (2 parity + shifted parity, intensity)
    for (int y = 2; y < camera.height - 2; ++y) {
      for (int x = 2; x < camera.width - 2; ++x) {
        double depth = 0.0, unused = 0.0;
        const int parity = predict(x, y, 0.0, &depth);
        if (parity < 0) continue;
        if (std::abs(frame.depth.at<float>(y, x) - depth) > 1e-3 * depth) continue;  // occluded
        bool interior = true;
        for (const auto& [dx, dy] : {std::pair{2, 0}, {-2, 0}, {0, 2}, {0, -2}}) {
          interior = interior && predict(x + dx, y + dy, 0.0, &unused) == parity;
        }
        if (!interior) continue;
        const int value = frame.image.at<uint8_t>(y, x);
        (parity == 1 ? dark : light).push_back(value);
        samples.emplace_back(parity * 2 + predict(x, y, 0.5, &unused), value);
      }
    }
    ASSERT_GT(dark.size(), 200u) << "frame " << index << " sees too little of the room's planes";
    ASSERT_GT(light.size(), 200u) << "frame " << index;
    std::nth_element(dark.begin(), dark.begin() + dark.size() / 2, dark.end());
    std::nth_element(light.begin(), light.begin() + light.size() / 2, light.end());
    const double dark_median = dark[dark.size() / 2], light_median = light[light.size() / 2];
    // Albedo 0.085 against 0.85, both under the same light: a ratio near 10.
    EXPECT_GT(light_median, 4.0 * dark_median) << "frame " << index;
    const double threshold = 0.5 * (dark_median + light_median);
    for (const auto& [parities, value] : samples) {
      const bool looks_dark = value < threshold;
      ++checked;
      agree += looks_dark == (parities / 2 == 1);
      shifted_agree += looks_dark == (parities % 2 == 1);
    }
    std::cout << "checkerboard frame " << index << ": " << dark.size() + light.size()
              << " pixels, medians dark " << dark_median << ", light " << light_median << "\n";
  }
  // The light's falloff varies the light squares' brightness across the room; nearly every
  // interior pixel still falls on its side of the threshold.
  EXPECT_GT(agree, 0.99 * checked);
  EXPECT_LT(shifted_agree, 0.7 * checked);
  std::cout << "checkerboard: " << agree << " / " << checked << " pixels as predicted, shifted by "
            << "half a square " << shifted_agree << "\n";
}

// The boxes stand where the preset says, and their silhouettes are depth discontinuities: the
// visible points of every box edge off the floor between a face turned to the camera and one
// turned away have, within 3 px, a surface more than kJump beyond them (the wall is 0.7-1.0 m
// behind a box, the furniture at least 0.05 m; a face itself recedes by a few cm over 3 px).
TEST(FailureFamiliesTest, BoxesMakeTheEdgesOcclusionBoundaries) {
  constexpr double kJump = 0.04;
  const SyntheticSequence sequence = MakeSequence(SmallOptions("boxes", 60));
  const Scene& scene = sequence.scene;
  const Eigen::Vector3d& room = scene.room_size();
  std::vector<const Primitive*> occluders;
  for (const Primitive& p : scene.primitives()) {
    if (p.name != "occluder") continue;
    occluders.push_back(&p);
    // Some wall has the box's back 0.7-1.0 m and its front at most 1.35 m from it.
    bool placed = false;
    for (int axis = 0; axis < 2; ++axis) {
      const double lo = p.center_in_world[axis] - p.half_size[axis];
      const double hi = p.center_in_world[axis] + p.half_size[axis];
      for (const auto& [back, front] :
           {std::pair{lo, hi}, std::pair{room[axis] - hi, room[axis] - lo}}) {
        placed = placed || (back >= 0.7 - 1e-9 && back <= 1.0 + 1e-9 && front <= 1.35 + 1e-9);
      }
    }
    EXPECT_TRUE(placed) << "occluder at " << p.center_in_world.transpose();
    EXPECT_NEAR(p.center_in_world.z(), p.half_size.z(), 1e-12);  // stands on the floor
  }
  EXPECT_EQ(occluders.size(), 16u);
  const PinholeCamera& camera = sequence.camera;
  int samples = 0, at_jump = 0;
  for (int index = 0; index < 60; index += 10) {
    const SE3& world_from_cam = sequence.ground_truth[index].world_from_cam;
    const SE3 cam_from_world = world_from_cam.Inverse();
    const Eigen::Vector3d origin = world_from_cam.translation();
    const RenderedFrame frame = RenderFrameForTest(sequence, index);
    for (const Primitive* box : occluders) {
      const Eigen::Vector3d& c = box->center_in_world;
      const Eigen::Vector3d& h = box->half_size;
      // Face (axis, sign) is turned to the camera.
      auto facing = [&](int axis, int sign) {
        return sign * (origin[axis] - (c[axis] + sign * h[axis])) > 0.0;
      };
      for (int axis = 0; axis < 3; ++axis) {  // the edge runs along axis
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        for (const int s1 : {-1, 1}) {
          for (const int s2 : {-1, 1}) {
            if ((a1 == 2 && s1 < 0) || (a2 == 2 && s2 < 0)) continue;  // on the floor
            if (facing(a1, s1) == facing(a2, s2)) continue;            // a crease, or hidden
            for (int k = 1; k < 10; ++k) {
              Eigen::Vector3d point = c;
              point[a1] += s1 * h[a1];
              point[a2] += s2 * h[a2];
              point[axis] += (0.2 * k - 1.0) * h[axis];
              const Eigen::Vector3d point_in_cam = cam_from_world * point;
              if (point_in_cam.z() < 0.1) continue;
              const Eigen::Vector2d pixel = camera.Project(point_in_cam);
              if (!camera.IsInside(pixel, 4.0)) continue;
              Scene::Hit hit;
              const Eigen::Vector3d direction = point - origin;
              if (!scene.Intersect(origin, direction, &hit) ||
                  hit.t < 1.0 - 0.01 / direction.norm()) {
                continue;  // occluded
              }
              ++samples;
              const int px = static_cast<int>(std::lround(pixel.x()));
              const int py = static_cast<int>(std::lround(pixel.y()));
              float far = 0.0f;
              for (int dy = -3; dy <= 3; ++dy) {
                for (int dx = -3; dx <= 3; ++dx) {
                  far = std::max(far, frame.depth.at<float>(py + dy, px + dx));
                }
              }
              at_jump += far > point_in_cam.z() + kJump;
            }
          }
        }
      }
    }
  }
  std::cout << "boxes: " << at_jump << " of " << samples << " visible silhouette points at a "
            << "depth jump > " << kJump << " m\n";
  EXPECT_GT(samples, 100);
  EXPECT_GT(at_jump, 0.9 * samples);
}

// Every seed of the family shows its boxes: in at least half of every 15th frame of a
// development-set sequence (640x480, 150 frames) the rendered depth puts >= 1% of the pixels on
// an occluder box (the 3D point within 2 mm of its volume). Seed 2's first path used to look past
// all 16 boxes: its frames were lowtex seed 2's, pixel for pixel.
TEST(FailureFamiliesTest, BoxesAreInViewForEverySeed) {
  PLDVO_RELEASE_ONLY_ACCURACY_TEST("FailureFamiliesTest.BoxesMakeTheEdgesOcclusionBoundaries");
  for (const int seed : {1, 2, 3}) {
    SynthOptions options = SmallOptions("boxes", 150, 640, 480);
    options.seed = seed;
    const SyntheticSequence sequence = MakeSequence(options);
    std::vector<const Primitive*> boxes;
    for (const Primitive& p : sequence.scene.primitives()) {
      if (p.name == kOccluderName) boxes.push_back(&p);
    }
    ASSERT_EQ(boxes.size(), 16u);
    const PinholeCamera& camera = sequence.camera;
    int checked = 0, showing = 0;
    for (int index = 0; index < options.frames; index += 15) {
      const RenderedFrame frame = RenderFrameForTest(sequence, index);
      const SE3& world_from_cam = sequence.ground_truth[index].world_from_cam;
      int on_boxes = 0;
      for (int y = 0; y < frame.depth.rows; y += 2) {
        for (int x = 0; x < frame.depth.cols; x += 2) {
          const float z = frame.depth.at<float>(y, x);
          if (!(z > 0.0f)) continue;
          const Eigen::Vector3d point =
              world_from_cam * (z * camera.Unproject(Eigen::Vector2d(x, y)));
          for (const Primitive* box : boxes) {
            const Eigen::Vector3d offset = (point - box->center_in_world).cwiseAbs();
            if ((offset - box->half_size).maxCoeff() < 0.002) {
              ++on_boxes;
              break;
            }
          }
        }
      }
      ++checked;
      showing += on_boxes * 4 >= 0.01 * camera.width * camera.height;
    }
    std::cout << "boxes seed " << seed << ": occluders in view in " << showing << " of " << checked
              << " frames\n";
    EXPECT_GE(2 * showing, checked) << seed;
  }
}

// Rotation rate of the ground truth between consecutive frames, deg/s; and the RMS of its
// camera-frame components.
TEST(FailureFamiliesTest, HandheldRotatesAtTumRpyRatesAboutAllAxes) {
  for (const int seed : {1, 2, 3}) {
    SynthOptions options = SmallOptions("handheld", 300, 160, 120);
    options.seed = seed;
    const SyntheticSequence sequence = MakeSequence(options);
    std::vector<double> rates;
    Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
    for (int i = 1; i < options.frames; ++i) {
      const Eigen::Matrix3d a = sequence.ground_truth[i - 1].world_from_cam.rotation_matrix();
      const Eigen::Matrix3d b = sequence.ground_truth[i].world_from_cam.rotation_matrix();
      const Eigen::Vector3d omega = LogSO3(a.transpose() * b) * options.fps * 180.0 / M_PI;
      rates.push_back(omega.norm());
      sum_sq += omega.cwiseAbs2();
    }
    double mean = 0.0;
    for (double rate : rates) mean += rate;
    mean /= rates.size();
    const double peak = *std::max_element(rates.begin(), rates.end());
    const Eigen::Vector3d rms = (sum_sq / rates.size()).cwiseSqrt();
    std::cout << "handheld seed " << seed << ": mean " << mean << " deg/s, peak " << peak
              << ", RMS per camera axis " << rms.transpose() << "\n";
    // TUM fr1/rpy: mean about 30-50 deg/s, peaks 60-90 (the brief of issue #41).
    EXPECT_GE(mean, 30.0) << seed;
    EXPECT_LE(mean, 50.0) << seed;
    EXPECT_GE(peak, 60.0) << seed;
    EXPECT_LE(peak, 110.0) << seed;
    // Roll, pitch and yaw all take part: no axis below a fifth of the total RMS.
    EXPECT_GT(rms.minCoeff(), 0.2 * rms.norm()) << seed;
  }
}

// With pivot_distance d the camera turns about a point d behind its centre: that point is at
// (0, 0, -d) in every frame's camera coordinates, the centre's frame-to-frame displacement is
// the point's plus d times the change of the optical axis.
TEST(FailureFamiliesTest, PivotCarriesTheCentreAlongTheTurn) {
  for (const int seed : {1, 2}) {
    SynthOptions options = SmallOptions("handheld", 150, 160, 120);
    options.seed = seed;
    options.pivot_distance = 0.25;
    const SyntheticSequence sequence = MakeSequence(options);
    double pivot_share = 0.0, speed = 0.0;
    for (int i = 0; i < options.frames; ++i) {
      const double time = i / options.fps;
      const SE3& world_from_cam = sequence.ground_truth[i].world_from_cam;
      const Eigen::Vector3d pivot = sequence.path.PositionInWorld(time);
      EXPECT_LT((world_from_cam.Inverse() * pivot - Eigen::Vector3d(0, 0, -0.25)).norm(), 1e-12);
      if (i == 0) continue;
      const SE3& previous = sequence.ground_truth[i - 1].world_from_cam;
      const Eigen::Vector3d axis_change =
          world_from_cam.rotation_matrix().col(2) - previous.rotation_matrix().col(2);
      pivot_share += 0.25 * axis_change.norm() * options.fps;
      speed += (world_from_cam.translation() - previous.translation()).norm() * options.fps;
    }
    pivot_share /= options.frames - 1;
    speed /= options.frames - 1;
    std::cout << "pivot seed " << seed << ": centre speed " << speed << " m/s, of the turns "
              << pivot_share << " m/s\n";
    // Yaw and pitch at 30-50 deg/s move a centre 0.25 m ahead by 0.1-0.2 m/s, about as fast as
    // the whole handheld path (0.15 m/s) moves without a pivot.
    EXPECT_GT(pivot_share, 0.1) << seed;
    EXPECT_GE(speed, 0.9 * pivot_share) << seed;
  }
  SynthOptions bad = SmallOptions("handheld", 10);
  bad.pivot_distance = -0.1;
  EXPECT_THROW(MakeSequence(bad), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo::synthetic
