// What the tracker aligns the current frame to: a reference keyframe's semi-dense points per
// pyramid level (pixel, inverse depth and its variance, reference intensity, the id of the edge
// it lies on) and, per level, the current-frame image line matched to each edge (paper Sec. IV:
// the photometric residuals of eq. 2 use every point, the point-to-line residuals of eq. 3
// the points whose edge has a matched line).
//
// Pyramid convention (core/pinhole_camera.h): level l halves level l-1; a level-l pixel u_l is
// the centre of a 2^l x 2^l block of level-0 pixels, u_0 = 2^l (u_l + 0.5) - 0.5.
#ifndef PLDVO_BACKEND_TRACKING_TRACKING_REFERENCE_H_
#define PLDVO_BACKEND_TRACKING_TRACKING_REFERENCE_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/options.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/covariance_models.h"

namespace pldvo {

struct ReferencePoint {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // in the reference image, at the level
  double idepth = 0.0;                              // 1/m, >= 0
  double idepth_var = 0.0;                          // (1/m)^2
  double intensity = 0.0;                           // I_ref(pixel) at the level, gray levels
  int edge_id = -1;  // index into TrackingReferenceLevel::lines_in_cur; -1: on no edge
  // The point the point-to-line residual reprojects: with mapping.edge_foot_points the foot
  // point of `pixel` on its edge's keyframe line at the level, otherwise (or when the line is
  // unknown) `pixel` itself.
  // Tracing puts edge pixels up to 1.5 px off the line, while an edge pixel's inverse depth is
  // that of the 3D line at the foot point (line-guided stereo, 3D line regularisation).
  Eigen::Vector2d pixel_on_edge = Eigen::Vector2d::Zero();
};

// The current-frame line matched to one reference edge, in the level's pixels.
struct MatchedLine {
  bool matched = false;
  LineWithCovariance line_in_cur;  // l = (a, b, c), a^2 + b^2 = 1, and its 3x3 covariance
};

struct TrackingReferenceLevel {
  PinholeCamera camera;  // the camera of this level
  std::vector<ReferencePoint> points;
  std::vector<MatchedLine> lines_in_cur;  // indexed by ReferencePoint::edge_id
};

struct TrackingReference {
  std::vector<TrackingReferenceLevel> levels;  // levels[0] is full resolution
  // sigma_I estimated from the previous frame's solution (EstimateIntensityNoiseSigma), gray
  // levels; the photometric weights use it where weighting.intensity_noise is estimated
  // (IntensityNoiseSigma). 0: none (the configured sigma_intensity).
  double intensity_noise_sigma = 0.0;
  // s of the line rows' covariance s^2 Sigma_l for the frames tracked against it, with
  // weighting.line_noise estimated (the previous frame's EstimateLineNoiseScale); 0: Sigma_l
  // unscaled.
  double line_noise_scale = 0.0;
  int num_levels() const { return static_cast<int>(levels.size()); }
};

// The matched current-frame line of `point`'s edge at `level`, or nullptr when the point is on
// no edge or its edge has no match. Throws std::invalid_argument when the edge id has no entry
// in `lines_in_cur` (an inconsistent reference).
const MatchedLine* MatchedLineOf(const TrackingReferenceLevel& ref, const ReferencePoint& point,
                                 int level);

// A level-0 line (with covariance) expressed in the pixels of `level`: with s = 2^level,
// l_level = (a, b, (a + b)(s - 1) / (2 s) + c / s), which keeps a^2 + b^2 = 1 and is linear in
// l for a normalised line, so Sigma_level = M Sigma M^T with that linear map M.
LineWithCovariance LineAtLevel(const LineWithCovariance& line_at_level0, int level);
// A level-0 pixel at `level`: u_l = (u_0 + 0.5) / 2^level - 0.5.
Eigen::Vector2d PixelAtLevel(const Eigen::Vector2d& pixel_at_level0, int level);
Eigen::Vector2d PixelAtLevel0(const Eigen::Vector2d& pixel_at_level, int level);

// Options of the ground-truth reference used by tests and experiments (no frontend).
struct GroundTruthReferenceOptions {
  int num_levels = 4;
  // Semi-dense selection: a pixel of level l is a point when |grad I_l| (central differences,
  // gray levels per level-l pixel) exceeds this.
  double gradient_threshold = 12.0;
  // Inverse-depth variance given to every GT point, (1/m)^2 (GT is exact; this only sets the
  // depth term of the covariance weights, eqs. 5-6). 1e-4 is a 1% inverse-depth sigma at 1 m.
  double idepth_var = 1e-4;
  // A level-l point's idepth is the mean of its 2^l x 2^l block of level-0 inverse depths
  // (exact on a plane, where inverse depth is affine in the pixel). The block grown by one
  // level-0 pixel per side must be consistent: (max - min) / mean below this, which rejects
  // depth discontinuities (occluding boundaries mix the intensities of two surfaces).
  double max_block_idepth_spread = 0.1;
  // Distance in pixels from the image border of every point.
  int border = 2;
  // Edge points are sampled along each projected edge every this many pixels of the level.
  double edge_sample_spacing_px = 1.0;
  // Endpoint noise of the ground-truth current lines at level 0 (sets Sigma_l), pixels.
  double line_sigma_px = 1.0;
  // Gaussian noise actually added to the GT current-line endpoints (pixels, level 0; 0: exact
  // lines), drawn from line_noise_seed; simulates a line detector's endpoint error.
  double line_noise_px = 0.0;
  int line_noise_seed = 1;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("num_levels", &num_levels, "Pyramid levels of the reference.");
    v.Field("gradient_threshold", &gradient_threshold,
            "Semi-dense selection: |grad I| threshold in gray levels per pixel of the level.");
    v.Field("idepth_var", &idepth_var, "Inverse-depth variance of every GT point, (1/m)^2.");
    v.Field("max_block_idepth_spread", &max_block_idepth_spread,
            "Reject level-l points whose level-0 inverse-depth block spreads more than this.");
    v.Field("border", &border, "Minimum distance of a point from the image border, pixels.");
    v.Field("edge_sample_spacing_px", &edge_sample_spacing_px,
            "Spacing of the points sampled along a GT edge, pixels of the level.");
    v.Field("line_sigma_px", &line_sigma_px,
            "Endpoint sigma assumed for the GT current lines' covariance, pixels.");
    v.Field("line_noise_px", &line_noise_px,
            "Gaussian noise added to the GT current-line endpoints, pixels (0: exact).");
    v.Field("line_noise_seed", &line_noise_seed, "Seed of that noise.");
  }
  std::string Check() const;
};

// A 3D edge segment in the reference camera frame.
struct EdgeSegment {
  Eigen::Vector3d start_in_ref = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_in_ref = Eigen::Vector3d::Zero();
};

// Semi-dense reference points from a reference image (CV_8U or CV_32F) and its ground-truth
// z-depth (CV_32F metres, 0 = no surface): per level, the pixels whose gradient exceeds the
// threshold, with idepth = mean of the level-0 inverse depths of their block. Throws
// std::invalid_argument on mismatched sizes or options. No edges, no lines.
TrackingReference MakeReferenceFromDepth(const cv::Mat& image, const cv::Mat& depth,
                                         const PinholeCamera& camera,
                                         const GroundTruthReferenceOptions& options);

// Adds ground-truth edges: for every 3D segment visible in the reference (its sampled points
// have a level-0 depth within 2% in their 3x3 neighbourhood, i.e. not occluded), points sampled
// along its projection (exact idepth from the 3D point; intensity from the reference image)
// with a new edge id, and as the edge's matched current line the projection of the segment
// with the ground-truth cur_from_ref (FitLine of the projected endpoints, clipped to z > 0.05 m
// and to the image, plus options.line_noise_px Gaussian endpoint noise, with covariance from
// options.line_sigma_px; unmatched when less than 10 px of it are inside the current image).
// Returns the number of edges that got points at level 0.
int AddGroundTruthEdges(const cv::Mat& image, const cv::Mat& depth,
                        const std::vector<EdgeSegment>& segments, const SE3& cur_from_ref,
                        const GroundTruthReferenceOptions& options, TrackingReference* reference);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_TRACKING_TRACKING_REFERENCE_H_
