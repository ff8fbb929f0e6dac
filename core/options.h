// The pattern every options struct follows, so that one set of visitors reads YAML, applies
// `--set key=value` overrides, writes the effective config and prints documentation, without
// any field being named twice:
//
//   struct TrackingOptions {
//     enum class Solver { kCeres, kGaussNewton };
//     Solver solver = Solver::kCeres;
//     int max_iterations = 20;
//     template <class Visitor>
//     void VisitFields(Visitor& v) {
//       v.Choice("solver", &solver,
//                {{"ceres", Solver::kCeres}, {"gauss_newton", Solver::kGaussNewton}},
//                "Solver of the tracking problem.");
//       v.Field("max_iterations", &max_iterations, "Gauss-Newton iterations per level.");
//     }
//     std::string Check() const;  // "" when valid, otherwise what is wrong.
//   };
//
// Field() takes bool, int, double, std::string and std::vector<double>; Choice() an enum with
// its names; Section("name", &sub_options, "doc") a nested struct with its own VisitFields.
// The visitors live in core/config_io.h.
#ifndef PLDVO_CORE_OPTIONS_H_
#define PLDVO_CORE_OPTIONS_H_

#include <string>
#include <utility>
#include <vector>

namespace pldvo {

// Name-value pairs of an enum field, in the order they are documented.
template <typename Enum>
using ChoiceNames = std::vector<std::pair<std::string, Enum>>;

}  // namespace pldvo

#endif  // PLDVO_CORE_OPTIONS_H_
