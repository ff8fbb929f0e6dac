#include "core/frame_range_view.h"

#include <stdexcept>

namespace pldvo {

FrameRangeView::FrameRangeView(const Dataset& dataset, int first, Direction direction)
    : dataset_(dataset),
      first_(first),
      step_(direction == Direction::kForward ? 1 : -1),
      size_(direction == Direction::kForward ? dataset.size() - first : first + 1) {
  if (first < 0 || first >= dataset.size()) {
    throw std::out_of_range("FrameRangeView: frame " + std::to_string(first) +
                            " is not one of the dataset's " + std::to_string(dataset.size()));
  }
}

int FrameRangeView::DatasetIndex(int i) const {
  if (i < 0 || i >= size_) {
    throw std::out_of_range("FrameRangeView: frame " + std::to_string(i) + " outside the view's " +
                            std::to_string(size_));
  }
  return first_ + step_ * i;
}

double FrameRangeView::timestamp(int i) const {
  const double first_time = dataset_.timestamp(first_);
  return first_time + step_ * (dataset_.timestamp(DatasetIndex(i)) - first_time);
}

Frame FrameRangeView::Load(int i) const {
  Frame frame = dataset_.Load(DatasetIndex(i));
  frame.index = i;
  frame.timestamp = timestamp(i);
  return frame;
}

}  // namespace pldvo
