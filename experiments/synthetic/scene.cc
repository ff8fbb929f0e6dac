// The synthetic room: random layout, analytic ray casting, edges and albedo textures.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "experiments/synthetic/synthetic_internal.h"
#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::synthetic {
namespace {

using internal::Rng;
using Pattern = Primitive::Pattern;

constexpr double kMinEdgeLength = 0.05;  // metres; shorter box edges are not listed
constexpr double kFlushTolerance = 1e-6;

Eigen::Matrix3d YawRotation(double yaw) {
  // box_from_world for a box turned by `yaw` about the world z axis.
  return Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// A wall of the room as a 2D frame: points on the floor start + s * along + d * inward.
struct WallFrame {
  Eigen::Vector2d start, along, inward;
  double length;
};

WallFrame MakeWallFrame(int wall, const Eigen::Vector3d& room) {
  switch (wall) {
    case 0:
      return {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, room.x()};
    case 1:
      return {{room.x(), 0.0}, {0.0, 1.0}, {-1.0, 0.0}, room.y()};
    case 2:
      return {{room.x(), room.y()}, {-1.0, 0.0}, {0.0, -1.0}, room.x()};
    default:
      return {{0.0, room.y()}, {0.0, -1.0}, {1.0, 0.0}, room.y()};
  }
}

// Builds the primitives of one scene; every piece of furniture is a set of boxes.
class SceneBuilder {
 public:
  SceneBuilder(Scene* scene, Rng* rng) : scene_(scene), rng_(rng) {}

  // An axis-aligned box against wall `wall`: along-wall [s0, s1], distance from the wall
  // [d0, d1], height [z0, z1].
  void WallBox(int wall, double s0, double s1, double d0, double d1, double z0, double z1,
               double albedo, Pattern pattern, double texture_scale, const std::string& name) {
    const WallFrame frame = MakeWallFrame(wall, scene_->room_size());
    Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
    for (double s : {s0, s1}) {
      for (double d : {d0, d1}) {
        const Eigen::Vector2d p = frame.start + s * frame.along + d * frame.inward;
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    Box(Eigen::Vector3d(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), 0.5 * (z0 + z1)),
        Eigen::Vector3d(0.5 * (hi.x() - lo.x()), 0.5 * (hi.y() - lo.y()), 0.5 * (z1 - z0)), 0.0,
        albedo, pattern, texture_scale, name);
  }

  void Box(const Eigen::Vector3d& center, const Eigen::Vector3d& half_size, double yaw,
           double albedo, Pattern pattern, double texture_scale, const std::string& name) {
    Primitive box;
    box.kind = Primitive::Kind::kBox;
    box.box_from_world_rotation = YawRotation(yaw);
    box.center_in_world = center;
    box.half_size = half_size;
    for (int f = 0; f < 6; ++f) {
      // Paint is uniform per object up to a slight per-face difference.
      box.albedo[f] = std::clamp(albedo + rng_->Uniform(-0.02, 0.02), 0.05, 0.95);
      box.pattern[f] = pattern;
    }
    box.texture_scale = texture_scale;
    box.texture_seed = static_cast<uint32_t>(rng_->Next());
    box.name = name;
    scene_->AddPrimitive(box);
  }

  // An albedo at least `min_difference` away from `avoid`.
  double AlbedoAwayFrom(double avoid, double lo, double hi, double min_difference) {
    for (int i = 0; i < 100; ++i) {
      const double a = rng_->Uniform(lo, hi);
      if (std::abs(a - avoid) >= min_difference) return a;
    }
    return avoid > 0.5 * (lo + hi) ? lo : hi;
  }

  Rng& rng() { return *rng_; }
  Scene& scene() { return *scene_; }

 private:
  Scene* scene_;
  Rng* rng_;
};

// Door with casing; returns the width used along the wall.
void AddDoor(SceneBuilder* b, int wall, double s0, double wall_albedo) {
  Rng& rng = b->rng();
  const double width = rng.Uniform(0.85, 0.95), height = rng.Uniform(2.0, 2.1);
  const double casing = 0.07;
  const double door_albedo = b->AlbedoAwayFrom(wall_albedo, 0.2, 0.85, 0.15);
  const double casing_albedo = b->AlbedoAwayFrom(door_albedo, 0.2, 0.9, 0.12);
  const double d0 = s0 + casing, d1 = d0 + width;
  b->WallBox(wall, d0, d1, 0.0, 0.03, 0.0, height, door_albedo, Pattern::kWood, 0.06, "door");
  b->WallBox(wall, s0, d0, 0.0, 0.045, 0.0, height + casing, casing_albedo, Pattern::kWood, 0.04,
             "door_casing");
  b->WallBox(wall, d1, d1 + casing, 0.0, 0.045, 0.0, height + casing, casing_albedo, Pattern::kWood,
             0.04, "door_casing");
  b->WallBox(wall, d0, d1, 0.0, 0.045, height, height + casing, casing_albedo, Pattern::kWood, 0.04,
             "door_casing");
  const bool handle_left = rng.Bernoulli(0.5);
  const double hs = handle_left ? d0 + 0.06 : d1 - 0.18;
  b->WallBox(wall, hs, hs + 0.12, 0.03, 0.08, 1.0, 1.03, 0.9 - 0.6 * (door_albedo > 0.5),
             Pattern::kPlain, 0.1, "door_handle");
}

// Cabinet body with one or two front doors.
void AddCabinet(SceneBuilder* b, int wall, double s0, double s1, double height,
                double wall_albedo) {
  Rng& rng = b->rng();
  const double depth = rng.Uniform(0.4, 0.6);
  const double albedo = b->AlbedoAwayFrom(wall_albedo, 0.15, 0.9, 0.15);
  b->WallBox(wall, s0, s1, 0.0, depth, 0.0, height, albedo, Pattern::kWood, 0.05, "cabinet");
  const int doors = (s1 - s0) > 0.8 ? 2 : 1;
  const double door_albedo = std::clamp(albedo + (albedo > 0.5 ? -0.12 : 0.12), 0.05, 0.95);
  const double margin = 0.03, plinth = 0.08;
  const double door_width = (s1 - s0 - (doors + 1) * margin) / doors;
  for (int i = 0; i < doors; ++i) {
    const double a0 = s0 + margin + i * (door_width + margin);
    b->WallBox(wall, a0, a0 + door_width, depth, depth + 0.02, plinth, height - margin, door_albedo,
               Pattern::kWood, 0.05, "cabinet_door");
    const double hz = std::min(height - 0.2, 0.9);
    const double hs = (i == 0 && doors == 2) ? a0 + door_width - 0.06 : a0 + 0.03;
    b->WallBox(wall, hs, hs + 0.03, depth + 0.02, depth + 0.05, hz - 0.08, hz + 0.08,
               door_albedo > 0.5 ? 0.2 : 0.85, Pattern::kPlain, 0.1, "cabinet_handle");
  }
}

// Open shelf: two sides, top, bottom, back panel, boards and blocks of books.
void AddShelf(SceneBuilder* b, int wall, double s0, double s1, double height, double wall_albedo) {
  Rng& rng = b->rng();
  const double depth = rng.Uniform(0.3, 0.4), t = 0.025, back = 0.01;
  const double albedo = b->AlbedoAwayFrom(wall_albedo, 0.15, 0.9, 0.18);
  const double back_albedo = std::clamp(albedo + (albedo > 0.5 ? -0.15 : 0.15), 0.05, 0.95);
  b->WallBox(wall, s0, s0 + t, 0.0, depth, 0.0, height, albedo, Pattern::kWood, 0.04, "shelf");
  b->WallBox(wall, s1 - t, s1, 0.0, depth, 0.0, height, albedo, Pattern::kWood, 0.04, "shelf");
  b->WallBox(wall, s0 + t, s1 - t, 0.0, back, 0.0, height, back_albedo, Pattern::kNoise, 0.1,
             "shelf_back");
  const int boards = rng.UniformInt(3, 4);
  const double base = 0.08;
  const double spacing = (height - base - t) / boards;
  for (int i = 0; i <= boards; ++i) {
    const double z0 = i == boards ? height - t : base + i * spacing;
    b->WallBox(wall, s0 + t, s1 - t, back, depth, z0, z0 + t, albedo, Pattern::kWood, 0.04,
               "shelf_board");
    if (i == boards) break;
    // Books standing on this board.
    double s = s0 + t + rng.Uniform(0.0, 0.15);
    while (true) {
      const double w = rng.Uniform(0.12, 0.35);
      if (s + w > s1 - t - 0.02) break;
      if (rng.Bernoulli(0.65)) {
        const double h = rng.Uniform(0.5, 0.85) * (spacing - t);
        const double book_albedo = b->AlbedoAwayFrom(back_albedo, 0.1, 0.9, 0.15);
        b->WallBox(wall, s, s + w, back, depth - rng.Uniform(0.02, 0.06), z0 + t, z0 + t + h,
                   book_albedo, Pattern::kNoise, 0.03, "books");
      }
      s += w + rng.Uniform(0.03, 0.2);
    }
  }
}

// Picture: canvas inside four frame strips.
void AddPicture(SceneBuilder* b, int wall, double s0, double s1, double z0, double z1,
                double wall_albedo) {
  const double frame_width = 0.04;
  const double frame_albedo = b->AlbedoAwayFrom(wall_albedo, 0.1, 0.9, 0.2);
  const double canvas_albedo = b->AlbedoAwayFrom(frame_albedo, 0.15, 0.9, 0.2);
  b->WallBox(wall, s0 + frame_width, s1 - frame_width, 0.0, 0.012, z0 + frame_width,
             z1 - frame_width, canvas_albedo, Pattern::kNoise, 0.04, "picture");
  b->WallBox(wall, s0, s0 + frame_width, 0.0, 0.03, z0, z1, frame_albedo, Pattern::kWood, 0.02,
             "picture_frame");
  b->WallBox(wall, s1 - frame_width, s1, 0.0, 0.03, z0, z1, frame_albedo, Pattern::kWood, 0.02,
             "picture_frame");
  b->WallBox(wall, s0 + frame_width, s1 - frame_width, 0.0, 0.03, z0, z0 + frame_width,
             frame_albedo, Pattern::kWood, 0.02, "picture_frame");
  b->WallBox(wall, s0 + frame_width, s1 - frame_width, 0.0, 0.03, z1 - frame_width, z1,
             frame_albedo, Pattern::kWood, 0.02, "picture_frame");
}

// Table with four legs and a box on it, turned by a random yaw, near the room centre.
void AddTable(SceneBuilder* b, double floor_albedo) {
  Rng& rng = b->rng();
  const Eigen::Vector3d& room = b->scene().room_size();
  const double yaw = rng.Uniform(-0.5, 0.5);
  const double length = rng.Uniform(1.1, 1.5), width = rng.Uniform(0.7, 0.85);
  const double height = rng.Uniform(0.72, 0.76), top = 0.04, leg = 0.05;
  // Several draws feeding one call are made first, last argument first (core/random_draws.h).
  const double center_dy = rng.Uniform(-0.4, 0.4);
  const double center_dx = rng.Uniform(-0.4, 0.4);
  const Eigen::Vector2d center(0.5 * room.x() + center_dx, 0.5 * room.y() + center_dy);
  const Eigen::Matrix2d world_from_table = Eigen::Rotation2Dd(yaw).toRotationMatrix();
  const double albedo = b->AlbedoAwayFrom(floor_albedo, 0.2, 0.85, 0.2);
  b->Box(Eigen::Vector3d(center.x(), center.y(), height - 0.5 * top),
         Eigen::Vector3d(0.5 * length, 0.5 * width, 0.5 * top), yaw, albedo, Pattern::kWood, 0.05,
         "table_top");
  for (int sx : {-1, 1}) {
    for (int sy : {-1, 1}) {
      const Eigen::Vector2d offset(sx * (0.5 * length - 0.08), sy * (0.5 * width - 0.08));
      const Eigen::Vector2d p = center + world_from_table * offset;
      b->Box(Eigen::Vector3d(p.x(), p.y(), 0.5 * (height - top)),
             Eigen::Vector3d(0.5 * leg, 0.5 * leg, 0.5 * (height - top)), yaw, albedo,
             Pattern::kWood, 0.05, "table_leg");
    }
  }
  // A box lying on the table at its own yaw.
  const double bx = rng.Uniform(0.2, 0.4), by = rng.Uniform(0.15, 0.3), bz = rng.Uniform(0.1, 0.25);
  const double offset_y = rng.Uniform(-0.2, 0.2) * width;
  const double offset_x = rng.Uniform(-0.25, 0.25) * length;
  const Eigen::Vector2d p = center + world_from_table * Eigen::Vector2d(offset_x, offset_y);
  const double box_albedo = b->AlbedoAwayFrom(albedo, 0.1, 0.9, 0.2);
  const double box_yaw = yaw + rng.Uniform(-0.8, 0.8);
  b->Box(Eigen::Vector3d(p.x(), p.y(), height + 0.5 * bz),
         Eigen::Vector3d(0.5 * bx, 0.5 * by, 0.5 * bz), box_yaw, box_albedo, Pattern::kNoise, 0.04,
         "box_on_table");
}

// Fills the four walls with doors, cabinets, shelves, gaps and pictures.
void FurnishWalls(SceneBuilder* b, const double wall_albedo[4]) {
  Rng& rng = b->rng();
  const Eigen::Vector3d& room = b->scene().room_size();
  const int door_wall = rng.UniformInt(0, 3);
  bool door_placed = false;
  constexpr double kCorner = 0.65;  // keeps furniture of adjacent walls apart
  for (int wall = 0; wall < 4; ++wall) {
    const double length = MakeWallFrame(wall, room).length;
    double s = kCorner + rng.Uniform(0.0, 0.3);
    while (s < length - kCorner) {
      const double left = length - kCorner - s;
      const double r = rng.Uniform();
      double used = 0.0, top = 0.0;  // along-wall width used and height of the object
      if (wall == door_wall && !door_placed && left > 1.2) {
        AddDoor(b, wall, s, wall_albedo[wall]);
        door_placed = true;
        used = 1.1;
        top = 2.2;
      } else if (r < 0.4 && left > 0.6) {
        used = std::min(left, rng.Uniform(0.6, 1.3));
        top = rng.Bernoulli(0.5) ? rng.Uniform(0.75, 1.0) : rng.Uniform(1.6, 2.1);
        AddCabinet(b, wall, s, s + used, top, wall_albedo[wall]);
      } else if (r < 0.7 && left > 0.7) {
        used = std::min(left, rng.Uniform(0.7, 1.2));
        top = rng.Uniform(1.5, 2.0);
        AddShelf(b, wall, s, s + used, top, wall_albedo[wall]);
      } else {
        used = std::min(left, rng.Uniform(0.5, 1.2));  // bare wall
      }
      // A picture above low furniture or bare wall.
      const double z0 = std::max(1.25, top + 0.25);
      const double z_max = room.z() - 0.35;
      if (top < 1.1 && used > 0.55 && z_max - z0 > 0.35 && rng.Bernoulli(0.8)) {
        const double w = rng.Uniform(0.4, std::min(1.0, used - 0.1));
        const double h = rng.Uniform(0.3, std::min(0.8, z_max - z0));
        const double ps = s + rng.Uniform(0.05, used - w - 0.05);
        const double pz = z0 + rng.Uniform(0.0, z_max - z0 - h);
        AddPicture(b, wall, ps, ps + w, pz, pz + h, wall_albedo[wall]);
      }
      s += used + rng.Uniform(0.1, 0.4);
    }
  }
}

double Frac(double x) { return x - std::floor(x); }

// Plain boxes standing on the floor in front of the walls, count / 4 per wall in equal stretches
// of it, 0.7-1.0 m between the wall and the box's back, 0.2-0.35 m deep (front faces at most
// 1.35 m from the wall, in front of the furniture, which reaches 0.65 m): their vertical outlines
// are depth discontinuities against the wall or the furniture behind.
void AddOccluderBoxes(SceneBuilder* b, int count, const double wall_albedo[4]) {
  Rng& rng = b->rng();
  const Eigen::Vector3d& room = b->scene().room_size();
  const int per_wall = (count + 3) / 4;
  for (int i = 0; i < count; ++i) {
    const int wall = i % 4, slot = i / 4;
    const WallFrame frame = MakeWallFrame(wall, room);
    const double stretch = (frame.length - 1.0) / per_wall;  // 0.5 m kept free at each corner
    // Several draws feeding one call are made first, last argument first (core/random_draws.h).
    const double albedo = b->AlbedoAwayFrom(wall_albedo[wall], 0.15, 0.9, 0.15);
    const double height = rng.Uniform(0.5, 1.6);
    const double depth = rng.Uniform(0.2, 0.35);
    const double gap = rng.Uniform(0.7, 1.0);
    const double width = std::min(rng.Uniform(0.4, 0.9), 0.9 * stretch);
    const double s0 = 0.5 + slot * stretch + rng.Uniform(0.0, stretch - width);
    b->WallBox(wall, s0, s0 + width, gap, gap + depth, 0.0, height, albedo, Pattern::kPlain, 0.1,
               kOccluderName);
  }
}

}  // namespace

void Scene::SetRoom(const Eigen::Vector3d& room_size) {
  room_size_ = room_size;
  // The room's own 12 edges.
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int c1 = 0; c1 < 2; ++c1) {
      for (int c2 = 0; c2 < 2; ++c2) {
        Eigen::Vector3d start = Eigen::Vector3d::Zero();
        start[a1] = c1 * room_size[a1];
        start[a2] = c2 * room_size[a2];
        Eigen::Vector3d end = start;
        end[axis] = room_size[axis];
        edges_.push_back({start, end});
      }
    }
  }
}

void Scene::AddPrimitive(const Primitive& primitive) {
  primitives_.push_back(primitive);
  if (primitive.kind != Primitive::Kind::kBox) return;
  const Eigen::Matrix3d world_from_box = primitive.box_from_world_rotation.transpose();
  const Eigen::Vector3d& h = primitive.half_size;
  // A face is flush with the room when it lies in a wall, floor or ceiling plane; an edge
  // between two flush faces sits in a room corner and is not a visible boundary.
  auto face_flush = [&](int axis, int sign) {
    const Eigen::Vector3d normal = world_from_box.col(axis) * sign;
    const Eigen::Vector3d on_face = primitive.center_in_world + normal * h[axis];
    for (int k = 0; k < 3; ++k) {
      if (std::abs(std::abs(normal[k]) - 1.0) > kFlushTolerance) continue;
      const double plane = normal[k] < 0 ? 0.0 : room_size_[k];
      if (std::abs(on_face[k] - plane) < 1e-6) return true;
    }
    return false;
  };
  for (int axis = 0; axis < 3; ++axis) {
    if (2.0 * h[axis] < kMinEdgeLength) continue;
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int s1 : {-1, 1}) {
      for (int s2 : {-1, 1}) {
        if (face_flush(a1, s1) && face_flush(a2, s2)) continue;
        Eigen::Vector3d corner_in_box = Eigen::Vector3d::Zero();
        corner_in_box[a1] = s1 * h[a1];
        corner_in_box[a2] = s2 * h[a2];
        Eigen::Vector3d start = corner_in_box, end = corner_in_box;
        start[axis] = -h[axis];
        end[axis] = h[axis];
        edges_.push_back({primitive.center_in_world + world_from_box * start,
                          primitive.center_in_world + world_from_box * end});
      }
    }
  }
}

Scene Scene::Generate(uint64_t seed, const SceneStyle& style) {
  Scene scene;
  Rng rng(seed * 0x2545F4914F6CDD1Dull + 17);
  // Several draws feeding one call are made first, last argument first (core/random_draws.h).
  const double room_z = rng.Uniform(2.5, 3.0);
  const double room_y = rng.Uniform(4.5, 7.0);
  const double room_x = rng.Uniform(4.5, 6.5);
  scene.SetRoom(Eigen::Vector3d(room_x, room_y, room_z));
  const Eigen::Vector3d& room = scene.room_size();
  const double light_dy = rng.Uniform(-0.5, 0.5);
  const double light_dx = rng.Uniform(-0.5, 0.5);
  scene.SetLight(
      Eigen::Vector3d(0.5 * room.x() + light_dx, 0.5 * room.y() + light_dy, room.z() - 0.5));

  // The room: walls of one paint (faces 0..3), floor (4), ceiling (5).
  Primitive interior;
  interior.kind = Primitive::Kind::kRoom;
  interior.center_in_world = 0.5 * room;
  interior.half_size = 0.5 * room;
  const double paint = rng.Uniform(0.55, 0.8);
  double wall_albedo[4];
  for (int f = 0; f < 4; ++f) {
    wall_albedo[f] = paint + rng.Uniform(-0.05, 0.05);
    interior.pattern[f] = Pattern::kNoise;
  }
  // Faces -x, +x, -y, +y map to walls 3, 1, 0, 2 of the wall frames.
  interior.albedo[0] = wall_albedo[3];
  interior.albedo[1] = wall_albedo[1];
  interior.albedo[2] = wall_albedo[0];
  interior.albedo[3] = wall_albedo[2];
  const double floor_albedo = rng.Uniform(0.25, 0.45);
  interior.albedo[4] = floor_albedo;
  interior.pattern[4] = rng.Bernoulli(0.5) ? Pattern::kWood : Pattern::kTiles;
  interior.albedo[5] = rng.Uniform(0.8, 0.9);
  interior.pattern[5] = Pattern::kNoise;
  interior.texture_scale = 0.15;
  interior.texture_seed = static_cast<uint32_t>(rng.Next());
  interior.name = "room";
  scene.primitives_.push_back(interior);

  SceneBuilder builder(&scene, &rng);
  FurnishWalls(&builder, wall_albedo);
  AddTable(&builder, floor_albedo);
  if (style.checker_size > 0.0) {
    // Black and white squares on the walls and the floor, aligned with the room's corner.
    Primitive& room_interior = scene.primitives_[0];
    for (int f = 0; f < 5; ++f) {
      room_interior.albedo[f] = 0.85;
      room_interior.pattern[f] = Pattern::kChecker;
    }
    room_interior.texture_scale = style.checker_size;
  }
  if (style.occluder_boxes > 0) {
    Rng occluder_rng(seed * 0x9E3779B97F4A7C15ull + 29);
    SceneBuilder occluders(&scene, &occluder_rng);
    AddOccluderBoxes(&occluders, style.occluder_boxes, wall_albedo);
  }
  return scene;
}

namespace {

// Slab test of a ray against a box in its own frame; returns the entry t and axis/face.
inline bool IntersectBox(const Primitive& box, const Eigen::Vector3d& origin,
                         const Eigen::Vector3d& direction, double t_max, double* t_hit, int* face) {
  const Eigen::Vector3d o = box.box_from_world_rotation * (origin - box.center_in_world);
  const Eigen::Vector3d d = box.box_from_world_rotation * direction;
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = t_max;
  int near_face = -1;
  for (int a = 0; a < 3; ++a) {
    const double h = box.half_size[a];
    if (std::abs(d[a]) < 1e-15) {
      if (std::abs(o[a]) > h) return false;
      continue;
    }
    const double inv = 1.0 / d[a];
    double t0 = (-h - o[a]) * inv, t1 = (h - o[a]) * inv;
    int f = 2 * a;  // entering through the -a face when moving towards +a
    if (t0 > t1) {
      std::swap(t0, t1);
      f = 2 * a + 1;
    }
    if (t0 > t_near) {
      t_near = t0;
      near_face = f;
    }
    if (t1 < t_far) t_far = t1;
    if (t_near > t_far) return false;
  }
  if (t_near <= 1e-9 || near_face < 0) return false;  // behind, or the origin inside the box
  *t_hit = t_near;
  *face = near_face;
  return true;
}

// Exit of a ray from the room interior (origin inside).
inline void IntersectRoom(const Primitive& room, const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& direction, double* t_hit, int* face) {
  const Eigen::Vector3d lo = room.center_in_world - room.half_size;
  const Eigen::Vector3d hi = room.center_in_world + room.half_size;
  double best = std::numeric_limits<double>::infinity();
  int best_face = -1;
  for (int a = 0; a < 3; ++a) {
    if (direction[a] > 1e-15) {
      const double t = (hi[a] - origin[a]) / direction[a];
      if (t < best) best = t, best_face = 2 * a + 1;
    } else if (direction[a] < -1e-15) {
      const double t = (lo[a] - origin[a]) / direction[a];
      if (t < best) best = t, best_face = 2 * a;
    }
  }
  *t_hit = best;
  *face = best_face;
}

}  // namespace

bool Scene::IntersectSubset(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                            const int* indices, int count, Hit* hit) const {
  double best_t = std::numeric_limits<double>::infinity();
  int best_primitive = -1, best_face = -1;
  for (int i = 0; i < count; ++i) {
    const Primitive& p = primitives_[indices[i]];
    double t;
    int face;
    if (p.kind == Primitive::Kind::kRoom) {
      IntersectRoom(p, origin, direction, &t, &face);
      if (face < 0 || t <= 0.0 || t >= best_t) continue;
    } else if (!IntersectBox(p, origin, direction, best_t, &t, &face) || t >= best_t) {
      continue;
    }
    best_t = t;
    best_primitive = indices[i];
    best_face = face;
  }
  if (best_primitive < 0) return false;
  const Primitive& p = primitives_[best_primitive];
  const int axis = best_face / 2;
  // Box faces point out of the box, room faces into the room.
  double sign = (best_face % 2 == 1) ? 1.0 : -1.0;
  if (p.kind == Primitive::Kind::kRoom) sign = -sign;
  hit->t = best_t;
  hit->primitive = best_primitive;
  hit->face = best_face;
  hit->normal_in_world = p.box_from_world_rotation.row(axis).transpose() * sign;
  return true;
}

bool Scene::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                      Hit* hit) const {
  thread_local std::vector<int> all;
  if (all.size() != primitives_.size()) {
    all.resize(primitives_.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  }
  return IntersectSubset(origin, direction, all.data(), static_cast<int>(all.size()), hit);
}

double Scene::DistanceToSurfaces(const Eigen::Vector3d& point_in_world) const {
  double distance = std::numeric_limits<double>::infinity();
  for (const Primitive& p : primitives_) {
    const Eigen::Vector3d q = p.box_from_world_rotation * (point_in_world - p.center_in_world);
    if (p.kind == Primitive::Kind::kRoom) {
      const Eigen::Vector3d gap = p.half_size - q.cwiseAbs();  // > 0 inside
      distance = std::min(distance, gap.minCoeff());
    } else {
      const Eigen::Vector3d outside = q.cwiseAbs() - p.half_size;
      const double d = outside.cwiseMax(0.0).norm() + std::min(outside.maxCoeff(), 0.0);
      distance = std::min(distance, d);
    }
  }
  return distance;
}

namespace {

// Band-limiting by the pixel response (PixelFootprint). A Gaussian of sigma pixels
// multiplies a sinusoid whose phase advances fx, fy cycles per pixel by its Fourier transform,
// exp(-2 pi^2 sigma^2 (fx^2 + fy^2)); `value` is pulled towards the pattern's `mean` by that
// factor.
double Attenuated(double value, double mean, double sigma_px, double fx, double fy) {
  if (sigma_px <= 0.0) return value;
  return mean +
         std::exp(-2.0 * M_PI * M_PI * sigma_px * sigma_px * (fx * fx + fy * fy)) * (value - mean);
}

// RMS frequency of value noise along one axis, cycles per lattice cell: the spectrum of a
// linearly interpolated lattice of i.i.d. values is sinc^4(f), whose second moment gives
// f_rms^2 = (1 / (2 pi^2)) / (2 / 3). The smoothstep interpolation of ValueNoise is treated
// alike; PixelFootprintTest measures the approximation against brute-force integration.
const double kValueNoiseRmsCycles = std::sqrt(3.0) / (2.0 * M_PI);

// Value noise at lattice coordinates (x, y), band-limited: its variance falls as
// exp(-4 pi^2 f_rms^2 tr(C)) to second order, C the footprint's covariance in lattice cells;
// cells_per_x, cells_per_y are the lattice cells crossed per pixel along x and y.
double FilteredValueNoise(double x, double y, uint32_t seed, double sigma_px, double cells_per_x,
                          double cells_per_y) {
  const double value = internal::ValueNoise(x, y, seed);
  return Attenuated(value, 0.5, sigma_px, kValueNoiseRmsCycles * cells_per_x,
                    kValueNoiseRmsCycles * cells_per_y);
}

// Fraction of a Gaussian of standard deviation `sigma` (face units) around r in [0, period)
// that falls on the bands [k period, k period + width): the nearest two bands.
double BandCoverage(double r, double period, double width, double sigma) {
  if (sigma <= 0.0) return r < width ? 1.0 : 0.0;
  const auto cdf = [sigma](double x) { return 0.5 * std::erfc(-x / (sigma * M_SQRT2)); };
  return cdf(width - r) - cdf(-r) + cdf(period + width - r) - cdf(period - r);
}

}  // namespace

int Scene::CheckerParity(const Hit& hit, const Eigen::Vector3d& point_in_world) const {
  const Primitive& p = primitives_[hit.primitive];
  if (p.pattern[hit.face] != Pattern::kChecker) return 0;
  const int axis = hit.face / 2;
  const Eigen::Vector3d q =
      p.box_from_world_rotation * (point_in_world - p.center_in_world) + p.half_size;
  const int64_t iu = static_cast<int64_t>(std::floor(q[(axis + 1) % 3] / p.texture_scale));
  const int64_t iv = static_cast<int64_t>(std::floor(q[(axis + 2) % 3] / p.texture_scale));
  return static_cast<int>((iu + iv) & 1);
}

PixelFootprint PixelFootprint::OnPlane(const Eigen::Vector3d& normal,
                                       const Eigen::Vector3d& direction, double t,
                                       const Eigen::Vector3d& ray_per_x,
                                       const Eigen::Vector3d& ray_per_y, double sigma_px) {
  PixelFootprint footprint;
  footprint.sigma_px = sigma_px;
  if (sigma_px <= 0.0) return footprint;
  // n . d kept 1e-9 away from 0 (a ray along the plane): the footprint is then so wide that the
  // pattern takes its mean, and finite.
  double n_d = normal.dot(direction);
  if (std::abs(n_d) < 1e-9) n_d = std::copysign(1e-9, n_d);
  footprint.point_per_x = t * (ray_per_x - direction * (normal.dot(ray_per_x) / n_d));
  footprint.point_per_y = t * (ray_per_y - direction * (normal.dot(ray_per_y) / n_d));
  return footprint;
}

double Scene::Albedo(const Hit& hit, const Eigen::Vector3d& point_in_world, double texture_contrast,
                     double albedo_variation, const PixelFootprint& footprint) const {
  const Primitive& p = primitives_[hit.primitive];
  const int axis = hit.face / 2;
  const int iu = (axis + 1) % 3, iv = (axis + 2) % 3;
  // Face coordinates: the two box-frame coordinates across the face, from the box corner.
  const Eigen::Vector3d q =
      p.box_from_world_rotation * (point_in_world - p.center_in_world) + p.half_size;
  const double u = q[iu], v = q[iv];
  const double sigma = footprint.sigma_px;
  Eigen::Vector2d uv_per_x = Eigen::Vector2d::Zero(), uv_per_y = Eigen::Vector2d::Zero();
  if (sigma > 0.0) {
    const Eigen::Vector3d dx = p.box_from_world_rotation * footprint.point_per_x;
    const Eigen::Vector3d dy = p.box_from_world_rotation * footprint.point_per_y;
    uv_per_x = Eigen::Vector2d(dx[iu], dx[iv]);
    uv_per_y = Eigen::Vector2d(dy[iu], dy[iv]);
  }
  double factor = 1.0;
  const uint32_t seed = p.texture_seed + 7919u * static_cast<uint32_t>(hit.face);
  if (p.pattern[hit.face] == Pattern::kChecker) {
    if (CheckerParity(hit, point_in_world) == 1) factor = kCheckerDark;
  } else if (texture_contrast > 0.0) {
    const double s = p.texture_scale;
    // Texture cells (of size s) crossed per pixel along x and y.
    const double cells_x = uv_per_x.norm() / s, cells_y = uv_per_y.norm() / s;
    double w = 0.5;
    switch (p.pattern[hit.face]) {
      case Pattern::kPlain:
      case Pattern::kChecker:  // handled above
        w = 0.5;
        break;
      case Pattern::kNoise:
        // Three octaves of value noise (fractal noise, in [0, 1]), each band-limited.
        w = (4.0 * FilteredValueNoise(u / s, v / s, seed, sigma, cells_x, cells_y) +
             2.0 * FilteredValueNoise(2.03 * (u / s), 2.03 * (v / s), seed + 1, sigma,
                                      2.03 * cells_x, 2.03 * cells_y) +
             FilteredValueNoise(4.07 * (u / s), 4.07 * (v / s), seed + 2, sigma, 4.07 * cells_x,
                                4.07 * cells_y)) /
            7.0;
        break;
      case Pattern::kWood: {
        // Bands across v, warped by low-frequency noise; the band's local frequency is the
        // phase difference across the footprint.
        const auto phase = [&](double pu, double pv) {
          return pv / s + 1.5 * internal::ValueNoise(pu / (6.0 * s), pv / (6.0 * s), seed);
        };
        double band = 0.5 + 0.5 * std::sin(2.0 * M_PI * phase(u, v));
        if (sigma > 0.0) {
          const auto cycles = [&](const Eigen::Vector2d& d) {
            return phase(u + 0.5 * d.x(), v + 0.5 * d.y()) -
                   phase(u - 0.5 * d.x(), v - 0.5 * d.y());
          };
          band = Attenuated(band, 0.5, sigma, cycles(uv_per_x), cycles(uv_per_y));
        }
        w = 0.7 * band + 0.3 * FilteredValueNoise(u / s, v / s, seed + 3, sigma, cells_x, cells_y);
        break;
      }
      case Pattern::kTiles: {
        // Tiles of one lattice value each, with dark grout: its coverage of the footprint.
        const double tile = 3.0 * s, grout = 0.012;
        const double cover_u = BandCoverage(Frac(u / tile) * tile, tile, grout,
                                            sigma * std::hypot(uv_per_x.x(), uv_per_y.x()));
        const double cover_v = BandCoverage(Frac(v / tile) * tile, tile, grout,
                                            sigma * std::hypot(uv_per_x.y(), uv_per_y.y()));
        const double face =
            0.25 +
            0.5 * internal::LatticeValue(static_cast<int64_t>(std::floor(u / tile)),
                                         static_cast<int64_t>(std::floor(v / tile)), seed) +
            0.25 * FilteredValueNoise(u / (0.3 * s), v / (0.3 * s), seed + 5, sigma, cells_x / 0.3,
                                      cells_y / 0.3);
        w = (1.0 - cover_u) * (1.0 - cover_v) * face;
        break;
      }
    }
    factor *= 1.0 + texture_contrast * (2.0 * w - 1.0);
  }
  if (albedo_variation > 0.0) {
    const Eigen::Vector3d r = point_in_world;  // 1 m cells in world coordinates
    const double n =
        internal::ValueNoise(r[(axis + 1) % 3], r[(axis + 2) % 3] + 0.37 * r[axis], seed + 11);
    factor *= 1.0 + albedo_variation * (2.0 * n - 1.0);
  }
  return p.albedo[hit.face] * factor;
}

}  // namespace pldvo::synthetic
