#include "backend/odometry/alternative_choice.h"

#include <algorithm>

namespace pldvo {
namespace {

// The correlation is defined over at least 2 photometric rows (LevelResult).
bool HasCorrelation(const LevelResult& level) { return level.photometric_valid_rows >= 2; }

}  // namespace

double AlternativeScore(const TrackingResult& result, OdometryOptions::AlternativeChoice choice) {
  if (result.levels.empty()) return 0.0;
  const LevelResult& finest = result.levels.back();
  const bool correlated =
      choice == OdometryOptions::AlternativeChoice::kCorrelatedInlierRows && HasCorrelation(finest);
  return correlated ? finest.inlier_rows * std::max(finest.intensity_correlation, 0.0)
                    : finest.inlier_rows;
}

bool BetterAlternative(const TrackingResult& a, const TrackingResult& b,
                       OdometryOptions::AlternativeChoice choice) {
  const bool a_lost = a.status == TrackingStatus::kLost;
  const bool b_lost = b.status == TrackingStatus::kLost;
  if (a_lost != b_lost) return !a_lost;
  if (choice == OdometryOptions::AlternativeChoice::kRowsAndCorrelation) {
    if (a.levels.empty() || b.levels.empty()) return !a.levels.empty();
    const LevelResult& fa = a.levels.back();
    const LevelResult& fb = b.levels.back();
    const bool correlated = HasCorrelation(fa) && HasCorrelation(fb);
    return fa.inlier_rows > fb.inlier_rows &&
           (!correlated || fa.intensity_correlation >= fb.intensity_correlation);
  }
  return AlternativeScore(a, choice) > AlternativeScore(b, choice);
}

double ImageMotion(const SE3& motion, double mean_idepth) {
  return motion.Log().tail<3>().norm() + motion.translation().norm() * mean_idepth;
}

bool BeyondPriorStep(const TrackingResult& alternative, const TrackingResult& first,
                     const SE3& prior_step, double mean_idepth) {
  const SE3 alternative_from_first = alternative.cur_from_ref * first.cur_from_ref.Inverse();
  return ImageMotion(alternative_from_first, mean_idepth) > ImageMotion(prior_step, mean_idepth);
}

bool AlternativeMayCompete(const TrackingResult& alternative, const TrackingResult& first,
                           const SE3& prior_step, double mean_idepth,
                           OdometryOptions::AlternativeChoice choice) {
  if (choice != OdometryOptions::AlternativeChoice::kMotionGatedInlierRows) return true;
  if (first.status == TrackingStatus::kLost || alternative.levels.empty() || first.levels.empty()) {
    return true;
  }
  const LevelResult& fa = alternative.levels.back();
  const LevelResult& ff = first.levels.back();
  if (!HasCorrelation(fa) || !HasCorrelation(ff)) return true;
  return !BeyondPriorStep(alternative, first, prior_step, mean_idepth) ||
         fa.intensity_correlation >= ff.intensity_correlation;
}

}  // namespace pldvo
