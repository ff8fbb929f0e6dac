// A run of a dataset's frames, forwards from a frame or backwards from it, as a Dataset of its
// own: view frame i is the dataset's frame first + i (forwards) or first - i (backwards). The
// re-anchored two-view start (docs/bootstrap.md) searches its second view from a later frame and
// tracks the frames before it backwards from its map.
#ifndef PLDVO_CORE_FRAME_RANGE_VIEW_H_
#define PLDVO_CORE_FRAME_RANGE_VIEW_H_

#include <string>

#include "core/dataset.h"

namespace pldvo {

class FrameRangeView : public Dataset {
 public:
  enum class Direction { kForward, kBackward };
  // Frames first, first + 1, ..., size - 1 (kForward) or first, first - 1, ..., 0 (kBackward) of
  // `dataset`, which must outlive the view. Throws std::out_of_range when first is not a frame.
  FrameRangeView(const Dataset& dataset, int first, Direction direction);

  std::string format() const override { return dataset_.format(); }
  int size() const override { return size_; }
  // Increasing in i either way: backwards, the times mirrored about the first frame's.
  double timestamp(int i) const override;
  // The dataset's frame, with index i and the view's timestamp.
  Frame Load(int i) const override;
  cv::Mat LoadDepth(int i) const override { return dataset_.LoadDepth(DatasetIndex(i)); }
  const PinholeCamera& camera() const override { return dataset_.camera(); }
  // None: the view's times are not the ground truth's.
  const Trajectory* ground_truth() const override { return nullptr; }

  // The dataset's index of view frame i (std::out_of_range outside the view).
  int DatasetIndex(int i) const;

 private:
  const Dataset& dataset_;
  const int first_;
  const int step_;  // +1 forwards, -1 backwards
  const int size_;
};

}  // namespace pldvo

#endif  // PLDVO_CORE_FRAME_RANGE_VIEW_H_
