// Test helpers: ground-truth image edges of a synthetic sequence and the association of detected
// segments to them.
//
// A scene edge (Scene::edges(), 3D segments in the world) is projected with the ground-truth
// pose and sampled every ~0.5 px; a sample is visible when it lies in front of the camera,
// inside the image (3 px border) and some pixel of its 3x3 neighbourhood has a rendered depth
// within 2% + 5 mm of the sample's depth (an edge lies on a surface boundary, so the pixel
// nearest to it may show the other surface). Runs of visible samples form the visible pieces.
// A piece's contrast is the mean |I(p + 2n) - I(p - 2n)| over its samples on the rendered
// image: edges between faces of equal brightness have no contrast and no detector can see
// them, so the tests only count pieces with contrast >= kMinContrast.
#ifndef PLDVO_TESTS_FRONTEND_LINE_GROUND_TRUTH_H_
#define PLDVO_TESTS_FRONTEND_LINE_GROUND_TRUTH_H_

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "experiments/synthetic/synthetic_sequence.h"
#include "frontend/line_segment.h"

namespace pldvo::test {

// Gray levels; the sensor noise is 1 gray level, so 10 is a clearly visible step.
constexpr double kMinContrast = 10.0;

struct GtPiece {
  int edge = -1;  // index into Scene::edges()
  Eigen::Vector2d start, end;
  double contrast = 0.0;
  double length() const { return (end - start).norm(); }
};

inline double SampleGray(const cv::Mat& image, const Eigen::Vector2d& p) {
  const int x = std::clamp(static_cast<int>(std::lround(p.x())), 0, image.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(p.y())), 0, image.rows - 1);
  return image.type() == CV_8U ? image.at<uint8_t>(y, x) : image.at<float>(y, x);
}

inline std::vector<GtPiece> VisibleEdgePieces(const synthetic::SyntheticSequence& sequence,
                                              const SE3& world_from_cam,
                                              const synthetic::RenderedFrame& frame,
                                              double min_length_px) {
  const PinholeCamera& camera = sequence.camera;
  const SE3 cam_from_world = world_from_cam.Inverse();
  std::vector<GtPiece> pieces;
  const auto& edges = sequence.scene.edges();
  for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
    const Eigen::Vector3d a = cam_from_world * edges[e].start_in_world;
    const Eigen::Vector3d b = cam_from_world * edges[e].end_in_world;
    if (a.z() < 0.05 && b.z() < 0.05) continue;
    // Parameter range with z >= 0.05.
    double t0 = 0.0, t1 = 1.0;
    if (a.z() < 0.05) t0 = (0.05 - a.z()) / (b.z() - a.z());
    if (b.z() < 0.05) t1 = (0.05 - a.z()) / (b.z() - a.z());
    const Eigen::Vector2d pa = camera.Project(a + t0 * (b - a));
    const Eigen::Vector2d pb = camera.Project(a + t1 * (b - a));
    const int n = std::clamp(static_cast<int>(2.0 * (pb - pa).norm()), 2, 20000);
    const Eigen::Vector2d dir2 = (pb - pa).normalized();
    const Eigen::Vector2d normal(-dir2.y(), dir2.x());
    GtPiece piece;
    int run = 0;
    double contrast_sum = 0.0;
    auto close_run = [&]() {
      if (run >= 2) {
        piece.contrast = contrast_sum / run;
        if (piece.length() >= min_length_px) pieces.push_back(piece);
      }
      run = 0;
      contrast_sum = 0.0;
    };
    for (int i = 0; i <= n; ++i) {
      const double t = t0 + (t1 - t0) * i / n;
      const Eigen::Vector3d p = a + t * (b - a);
      const Eigen::Vector2d pixel = camera.Project(p);
      bool visible = camera.IsInside(pixel, 3.0);
      if (visible) {
        visible = false;
        const int px = static_cast<int>(std::lround(pixel.x()));
        const int py = static_cast<int>(std::lround(pixel.y()));
        for (int dy = -1; dy <= 1 && !visible; ++dy) {
          for (int dx = -1; dx <= 1 && !visible; ++dx) {
            const float depth = frame.depth.at<float>(py + dy, px + dx);
            visible = depth > 0.f && std::abs(depth - p.z()) < 0.02 * p.z() + 0.005;
          }
        }
      }
      if (!visible) {
        close_run();
        continue;
      }
      if (run == 0) {
        piece = GtPiece();
        piece.edge = e;
        piece.start = pixel;
      }
      piece.end = pixel;
      contrast_sum += std::abs(SampleGray(frame.image, pixel + 2.0 * normal) -
                               SampleGray(frame.image, pixel - 2.0 * normal));
      ++run;
    }
    close_run();
  }
  return pieces;
}

// Undirected angle between two directions, radians in [0, pi/2].
inline double UndirectedAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

// True when point p lies within `distance_px` of the segment a-b (perpendicular) and its
// projection falls within the segment extended by `distance_px`.
inline bool NearSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Vector2d& p, double distance_px) {
  const double length = (b - a).norm();
  const Eigen::Vector2d d = (b - a) / length;
  const double t = d.dot(p - a);
  const double perp = std::abs(d.x() * (p - a).y() - d.y() * (p - a).x());
  return perp <= distance_px && t >= -distance_px && t <= length + distance_px;
}

// Fraction of a GT piece (sampled every pixel) covered by detected segments within
// `distance_px` and `angle_rad`.
inline double Coverage(const GtPiece& piece, const std::vector<LineSegment>& segments,
                       double distance_px, double angle_rad) {
  const Eigen::Vector2d d = piece.end - piece.start;
  std::vector<const LineSegment*> near;
  for (const LineSegment& s : segments) {
    if (UndirectedAngle(s.end - s.start, d) <= angle_rad) near.push_back(&s);
  }
  const int n = std::max(2, static_cast<int>(piece.length()));
  int covered = 0;
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector2d p = piece.start + d * (static_cast<double>(i) / n);
    for (const LineSegment* s : near) {
      if (NearSegment(s->start, s->end, p, distance_px)) {
        ++covered;
        break;
      }
    }
  }
  return static_cast<double>(covered) / (n + 1);
}

// The GT edge a detected segment lies on: the edge whose visible pieces (any length, together:
// the depth test may split one edge into several runs) contain at least `min_fraction` of the
// segment's samples within `distance_px` and `angle_rad`; -1 if none.
inline int AssociateSegment(const LineSegment& segment, const std::vector<GtPiece>& pieces,
                            double distance_px, double angle_rad, double min_fraction) {
  const int n = std::max(2, static_cast<int>(segment.length / 2.0));
  std::vector<const GtPiece*> parallel;
  for (const GtPiece& piece : pieces) {
    if (UndirectedAngle(piece.end - piece.start, segment.end - segment.start) <= angle_rad) {
      parallel.push_back(&piece);
    }
  }
  int best_edge = -1, best_count = 0;
  std::vector<int> edges_tried;
  for (const GtPiece* candidate : parallel) {
    const int edge = candidate->edge;
    if (std::find(edges_tried.begin(), edges_tried.end(), edge) != edges_tried.end()) continue;
    edges_tried.push_back(edge);
    int count = 0;
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d p = segment.start + (segment.end - segment.start) * (double(i) / n);
      for (const GtPiece* piece : parallel) {
        if (piece->edge == edge && NearSegment(piece->start, piece->end, p, distance_px)) {
          ++count;
          break;
        }
      }
    }
    if (count > best_count) {
      best_count = count;
      best_edge = edge;
    }
  }
  return best_count >= min_fraction * (n + 1) ? best_edge : -1;
}

// The full projection of scene edge `edge` (clipped to z >= 0.05 m, occlusion ignored) as a
// one-piece list for AssociateSegment; empty when it lies behind the camera.
inline std::vector<GtPiece> ProjectedEdge(const synthetic::SyntheticSequence& sequence,
                                          const SE3& world_from_cam, int edge) {
  const SE3 cam_from_world = world_from_cam.Inverse();
  const Eigen::Vector3d a = cam_from_world * sequence.scene.edges()[edge].start_in_world;
  const Eigen::Vector3d b = cam_from_world * sequence.scene.edges()[edge].end_in_world;
  if (a.z() < 0.05 && b.z() < 0.05) return {};
  double t0 = 0.0, t1 = 1.0;
  if (a.z() < 0.05) t0 = (0.05 - a.z()) / (b.z() - a.z());
  if (b.z() < 0.05) t1 = (0.05 - a.z()) / (b.z() - a.z());
  GtPiece piece;
  piece.edge = edge;
  piece.start = sequence.camera.Project(a + t0 * (b - a));
  piece.end = sequence.camera.Project(a + t1 * (b - a));
  return {piece};
}

// Outcome of a match between a reference segment (frame pose world_from_ref, associated edge
// edge_ref or -1) and a current segment (world_from_cur, edge_cur or -1).
enum class MatchOutcome { kCorrect, kWrong, kUnverifiable };

// A match is correct when both segments lie on the same scene edge. Scene edges that project
// within 2 px of each other (the front and back edges of a thin board seen edge-on, 2 cm apart)
// are indistinguishable in the image, so it suffices that one segment lies on the full
// projection of the other's edge along most (half) of it, the criterion of the detection
// recall. Unverifiable: neither segment lies on any scene edge.
inline MatchOutcome JudgeMatch(const synthetic::SyntheticSequence& sequence, const LineSegment& ref,
                               const SE3& world_from_ref, int edge_ref, const LineSegment& cur,
                               const SE3& world_from_cur, int edge_cur) {
  constexpr double kDistancePx = 2.0, kAngleRad = 5.0 * M_PI / 180.0, kFraction = 0.5;
  if (edge_ref < 0 && edge_cur < 0) return MatchOutcome::kUnverifiable;
  if (edge_ref == edge_cur) return MatchOutcome::kCorrect;
  if (edge_ref >= 0 && AssociateSegment(cur, ProjectedEdge(sequence, world_from_cur, edge_ref),
                                        kDistancePx, kAngleRad, kFraction) >= 0) {
    return MatchOutcome::kCorrect;
  }
  if (edge_cur >= 0 && AssociateSegment(ref, ProjectedEdge(sequence, world_from_ref, edge_cur),
                                        kDistancePx, kAngleRad, kFraction) >= 0) {
    return MatchOutcome::kCorrect;
  }
  return MatchOutcome::kWrong;
}

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_FRONTEND_LINE_GROUND_TRUTH_H_
