// The per-pixel passes of the mapping (stereo, smoothing) in stripes on OpenCV's thread pool:
// each stripe touches only its own pixels and counters, so results do not depend on the count.
#ifndef PLDVO_BACKEND_MAPPING_PIXEL_STRIPES_H_
#define PLDVO_BACKEND_MAPPING_PIXEL_STRIPES_H_

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <utility>
#include <vector>

#include "backend/mapping/mapping_options.h"

namespace pldvo {

// options.num_threads, or cv::getNumThreads() for 0.
inline int NumStripes(const MappingOptions& options) {
  return options.num_threads > 0 ? options.num_threads : std::max(1, cv::getNumThreads());
}

// Calls body(stripe) for every stripe in [0, stripes): with cv::parallel_for_, or on the calling
// thread for a single stripe.
template <typename Body>
void ForEachStripe(int stripes, const Body& body) {
  const auto run = [&body](const cv::Range& range) {
    for (int stripe = range.start; stripe < range.end; ++stripe) body(stripe);
  };
  if (stripes <= 1) {
    run(cv::Range(0, 1));
  } else {
    cv::parallel_for_(cv::Range(0, stripes), run, stripes);
  }
}

// Calls row(y, &found) for the rows [0, height) in stripes of rows and returns what they appended
// to `found`, in raster order, whatever the stripe count: a pass that reads a map in stripes and
// changes it afterwards.
template <typename T, typename Row>
std::vector<T> CollectRowsInStripes(int height, int stripes, const Row& row) {
  std::vector<std::vector<T>> found(stripes);
  ForEachStripe(stripes, [&](int stripe) {
    const int y_end = height * (stripe + 1) / stripes;
    for (int y = height * stripe / stripes; y < y_end; ++y) row(y, &found[stripe]);
  });
  std::vector<T> all = std::move(found[0]);
  for (int stripe = 1; stripe < stripes; ++stripe) {
    all.insert(all.end(), found[stripe].begin(), found[stripe].end());
  }
  return all;
}

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_PIXEL_STRIPES_H_
