// Frame pairs from the synthetic renderer with ground-truth depth, poses and 3D edges, and the
// ground-truth tracking reference of a pair (header-only; link pldvo_backend and
// pldvo_synthetic). Used by the tracking tests, `pldvo basin`, `pldvo mapeval` and the tracking
// and mapping benchmarks.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_SYNTHETIC_PAIRS_H_
#define PLDVO_EXPERIMENTS_EVALUATION_SYNTHETIC_PAIRS_H_

#include <cmath>
#include <string>
#include <vector>

#include "backend/tracking/tracking_reference.h"
#include "core/image_pyramid.h"
#include "core/se3.h"
#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::synthetic_pairs {

// A sequence of the given preset at width x height with the focal length scaled from 525 px at
// 640x480 (so every size sees the same field of view).
inline synthetic::SyntheticSequence MakeScaledSequence(const std::string& preset, int frames,
                                                       int seed = 1, int width = 320,
                                                       int height = 240) {
  synthetic::SynthOptions options;
  options.preset = preset;
  options.frames = frames;
  options.seed = seed;
  options.width = width;
  options.height = height;
  options.fx = 525.0 * width / 640.0;
  options.fy = 525.0 * height / 480.0;
  return synthetic::MakeSequence(options);
}

// The scene's 3D edges in a camera's frame.
inline std::vector<EdgeSegment> SegmentsInCam(const synthetic::Scene& scene,
                                              const SE3& cam_from_world) {
  std::vector<EdgeSegment> segments;
  segments.reserve(scene.edges().size());
  for (const synthetic::Segment3d& edge : scene.edges()) {
    segments.push_back({cam_from_world * edge.start_in_world, cam_from_world * edge.end_in_world});
  }
  return segments;
}

struct FramePair {
  PinholeCamera camera;
  cv::Mat ref_image, ref_depth, cur_image;
  SE3 cur_from_ref;  // ground truth
  std::vector<EdgeSegment> segments_in_ref;
};

inline FramePair MakeFramePair(const synthetic::SyntheticSequence& sequence, int ref_index,
                               int cur_index) {
  FramePair pair;
  pair.camera = sequence.camera;
  const synthetic::RenderedFrame ref = synthetic::RenderFrame(sequence, ref_index);
  pair.ref_image = ref.image;
  pair.ref_depth = ref.depth;
  pair.cur_image = synthetic::RenderFrame(sequence, cur_index).image;
  const SE3& world_from_ref = sequence.ground_truth[ref_index].world_from_cam;
  const SE3& world_from_cur = sequence.ground_truth[cur_index].world_from_cam;
  pair.cur_from_ref = world_from_cur.Inverse() * world_from_ref;
  pair.segments_in_ref = SegmentsInCam(sequence.scene, world_from_ref.Inverse());
  return pair;
}

// The reference of a pair: semi-dense GT-depth points, plus GT edges with their GT lines.
inline TrackingReference MakePairReference(const FramePair& pair,
                                           const GroundTruthReferenceOptions& options,
                                           bool with_edges) {
  TrackingReference reference =
      MakeReferenceFromDepth(pair.ref_image, pair.ref_depth, pair.camera, options);
  if (with_edges) {
    AddGroundTruthEdges(pair.ref_image, pair.ref_depth, pair.segments_in_ref, pair.cur_from_ref,
                        options, &reference);
  }
  return reference;
}

// Translation error in metres and rotation error in degrees of an estimate.
inline double TranslationError(const SE3& estimate, const SE3& truth) {
  return (estimate * truth.Inverse()).translation().norm();
}
inline double RotationErrorDeg(const SE3& estimate, const SE3& truth) {
  return LogSO3((estimate * truth.Inverse()).rotation_matrix()).norm() * 180.0 / M_PI;
}

}  // namespace pldvo::synthetic_pairs

#endif  // PLDVO_EXPERIMENTS_EVALUATION_SYNTHETIC_PAIRS_H_
