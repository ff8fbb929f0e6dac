// The input of windowed photometric + line bundle adjustment (docs/windowed_ba.md): the newest
// keyframes with their images, poses, brightness, semi-dense points (from the depth filter) and
// the lines matched to their edges in other keyframes. The images are shared, not copied.
//
// Conventions: poses are cam_from_world; pixels, lines and the camera at full resolution
// (pyramid level 0); a keyframe's brightness {a, b} models its image as I = e^a L + b of a
// common radiance L (residuals/host_target_photometric_residual.h).
#ifndef PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_WINDOW_H_
#define PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_WINDOW_H_

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "backend/windowed_ba/windowed_ba_prior.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/affine_brightness.h"
#include "residuals/covariance_models.h"

namespace pldvo {

// A semi-dense point of a keyframe: a candidate for the BA's point selection.
struct WindowedBAPoint {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double idepth = 0.0;      // > 0, keyframe frame
  double idepth_var = 0.0;  // > 0, the depth filter's variance V (eq. 5, eq. 6)
  int edge_id = -1;         // keyframe-local edge the point lies on, -1: none
};

// A keyframe's edge matched to a line observed in another keyframe of the window.
struct WindowedBALineObservation {
  int edge_id = -1;                   // the host keyframe's edge
  int target_id = -1;                 // WindowedBAKeyframe::id of the observing keyframe
  LineWithCovariance line_in_target;  // a^2 + b^2 = 1, with Sigma_l (FitLine)
};

struct WindowedBAKeyframe {
  int id = -1;
  SE3 cam_from_world;
  AffineBrightness brightness;
  std::shared_ptr<const ImagePyramid> pyramid;  // level 0 the camera's size
  std::vector<WindowedBAPoint> points;
  std::vector<WindowedBALineObservation> line_observations;
};

struct WindowedBAWindow {
  PinholeCamera camera;
  // Oldest first, strictly increasing ids. Only the newest WindowedBAOptions::window are used.
  std::vector<WindowedBAKeyframe> keyframes;
  // What earlier windows left when their oldest keyframes left (WindowedBAOptions::marginalize);
  // null: none.
  std::shared_ptr<const WindowedBAPrior> prior;
  // sigma_I (gray levels) that tracking estimated from its newest frame's photometric errors;
  // with weighting.intensity_noise estimated it replaces weighting.sigma_intensity in eq. 5,
  // which keeps the photometric rows' weight relative to the line rows and the priors
  // independent of the image's contrast. 0: none (the configured sigma_intensity).
  double intensity_noise_sigma = 0.0;
};

// Throws std::invalid_argument naming the keyframe / point when the window is malformed (invalid
// camera, fewer than 2 keyframes, a negative or non-finite intensity_noise_sigma, ids not
// increasing, missing pyramid or one whose level 0 differs from the camera, non-finite pose, a
// point with non-finite pixel or non-positive idepth / idepth_var, a line observation whose line is
// not normalised, a malformed prior).
void CheckWindowedBAWindow(const WindowedBAWindow& window);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_WINDOW_H_
