// FrameRangeView (core/frame_range_view.h): indices, times and images of a forward and a
// backward view, and frames outside them.
#include "core/frame_range_view.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace pldvo {
namespace {

// Five frames at uneven times; frame i's image is filled with i.
class FiveFrames : public Dataset {
 public:
  std::string format() const override { return "test"; }
  int size() const override { return static_cast<int>(times_.size()); }
  double timestamp(int i) const override { return times_.at(i); }
  Frame Load(int i) const override {
    Frame frame;
    frame.index = i;
    frame.timestamp = timestamp(i);
    frame.image = cv::Mat(2, 3, CV_32F, cv::Scalar(i));
    return frame;
  }
  const PinholeCamera& camera() const override { return camera_; }
  const Trajectory* ground_truth() const override { return &ground_truth_; }

 private:
  std::vector<double> times_{10.0, 10.1, 10.25, 10.3, 10.5};
  PinholeCamera camera_{3, 2, 1.0, 1.0, 1.0, 0.5};
  Trajectory ground_truth_;
};

TEST(FrameRangeViewTest, ForwardViewStartsAtItsFirstFrame) {
  const FiveFrames dataset;
  const FrameRangeView view(dataset, 2, FrameRangeView::Direction::kForward);
  ASSERT_EQ(view.size(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(view.DatasetIndex(i), 2 + i);
    EXPECT_DOUBLE_EQ(view.timestamp(i), dataset.timestamp(2 + i));
    const Frame frame = view.Load(i);
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.image.at<float>(0, 0), 2 + i);
  }
  EXPECT_EQ(view.ground_truth(), nullptr);
  EXPECT_EQ(view.camera().width, 3);
}

TEST(FrameRangeViewTest, BackwardViewRunsToFrameZeroWithMirroredTimes) {
  const FiveFrames dataset;
  const FrameRangeView view(dataset, 3, FrameRangeView::Direction::kBackward);
  ASSERT_EQ(view.size(), 4);
  const std::vector<double> expected{10.3, 10.35, 10.5, 10.6};  // 2 x 10.3 - t(3 - i)
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(view.DatasetIndex(i), 3 - i);
    EXPECT_NEAR(view.timestamp(i), expected[i], 1e-12);
    EXPECT_EQ(view.Load(i).image.at<float>(0, 0), 3 - i);
  }
}

TEST(FrameRangeViewTest, FramesOutsideAreErrors) {
  const FiveFrames dataset;
  EXPECT_THROW(FrameRangeView(dataset, 5, FrameRangeView::Direction::kForward), std::out_of_range);
  EXPECT_THROW(FrameRangeView(dataset, -1, FrameRangeView::Direction::kBackward),
               std::out_of_range);
  const FrameRangeView view(dataset, 1, FrameRangeView::Direction::kBackward);
  EXPECT_THROW(view.Load(2), std::out_of_range);
  EXPECT_THROW(view.DatasetIndex(-1), std::out_of_range);
}

}  // namespace
}  // namespace pldvo
