// Summary statistics of samples: the one definition of the median and the mean that evaluation,
// the experiments' tables and the tests share.
//
// Median: the middle value of the sorted samples; for an even count, the mean of the two middle
// values (numpy.median's rule, and the one the `pldvo ablate` tables have always used). No
// samples give 0, as does Mean: callers that must tell "no data" apart check for emptiness first.
#ifndef PLDVO_CORE_STATISTICS_H_
#define PLDVO_CORE_STATISTICS_H_

#include <vector>

namespace pldvo {

// {1, 3, 2} -> 2; {4, 1, 3, 2} -> 2.5 (the mean of 2 and 3); {} -> 0. O(n) (nth_element).
double Median(std::vector<double> values);

// The sample at rank n / 2 of the sorted values: the median for an odd count, the upper of the
// two middle values for an even count. A threshold test on a per-edge median (the line gates of
// backend/odometry/reference_builder.h) compares with one of the samples; {} -> 0. O(n).
double UpperMedian(std::vector<double> values);

// The arithmetic mean; {} -> 0.
double Mean(const std::vector<double>& values);

}  // namespace pldvo

#endif  // PLDVO_CORE_STATISTICS_H_
