#include "render/terrain_renderer.h"

#include <algorithm>
#include <cmath>

#include "core/stage_times.h"
#include "render/course_boards.h"
#include "render/detail_texture.h"
#include "render/gl.h"
#include "render/ground_objects.h"

namespace nadir::render {
namespace {

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 local_ned;
uniform mat4 u_clip_from_local;
uniform float u_size_m;
uniform float u_texture_px;
uniform vec2 u_detail_origin_1;
uniform vec2 u_detail_origin_2;
uniform mat2 u_detail_rotation_2;
out vec2 v_uv;
out vec2 v_detail_1;
out vec2 v_detail_2;
const float kDetailRepeat1_m = 10.24;
uniform float u_detail_repeat_2_m;
void main() {
  gl_Position = u_clip_from_local * vec4(local_ned, 1.0);
  // Texture row 0 is the north edge; one border texel on each side.
  float texels = u_texture_px + 2.0;
  v_uv = vec2((1.0 + local_ned.y / u_size_m * u_texture_px) / texels,
              (1.0 + (u_size_m - local_ned.x) / u_size_m * u_texture_px) / texels);
  v_detail_1 = (u_detail_origin_1 + local_ned.yx) / kDetailRepeat1_m;
  v_detail_2 = (u_detail_origin_2 + u_detail_rotation_2 * local_ned.yx) / u_detail_repeat_2_m;
}
)";

constexpr const char* kFragmentShader = R"(
in vec2 v_uv;
in vec2 v_detail_1;
in vec2 v_detail_2;
uniform sampler2D u_imagery;
uniform sampler2D u_detail;
uniform float u_gain;
uniform float u_detail_contrast;
uniform float u_texel_m;
uniform bool u_gray;
out vec4 out_colour;
void main() {
  vec3 colour = texture(u_imagery, v_uv).rgb * u_gain;
#ifdef GROUND_DETAIL
  // Only where a pixel is finer than the imagery's texel does the detail fade
  // in (fully at a quarter texel): from higher up the imagery alone is drawn.
  float pixel_m = length(fwidth(v_detail_1)) * 10.24;
  float weight = clamp(log2(u_texel_m / pixel_m) * 0.5, 0.0, 1.0);
  if (weight > 0.0) {
    // Multiplicative, so the detail follows the imagery's brightness.
    float detail = (texture(u_detail, v_detail_1).r - 0.5) + 0.8 * (texture(u_detail, v_detail_2).r - 0.5);
    colour *= 1.0 + 2.0 * u_detail_contrast * weight * detail;
  }
#endif
  if (u_gray) {
    out_colour = vec4(dot(colour, vec3(0.299, 0.587, 0.114)), 0.0, 0.0, 1.0);
  } else {
    out_colour = vec4(colour, 1.0);
  }
}
)";

constexpr const char* kTargetVertexShader = R"(#version 450 core
layout(location = 0) in vec3 local_ned;
layout(location = 1) in vec2 uv;
uniform mat4 u_clip_from_local;
out vec2 v_uv;
void main() {
  gl_Position = u_clip_from_local * vec4(local_ned, 1.0);
  v_uv = uv;
}
)";

constexpr const char* kTargetFragmentShader = R"(#version 450 core
in vec2 v_uv;
uniform sampler2D u_texture;
uniform float u_gain;
uniform bool u_gray;
out vec4 out_colour;
void main() {
  vec3 colour = texture(u_texture, v_uv).rgb * u_gain;
  out_colour = u_gray ? vec4(dot(colour, vec3(0.299, 0.587, 0.114)), 0.0, 0.0, 1.0) : vec4(colour, 1.0);
}
)";

// Texture resolution of a target mat: fine enough for a camera a metre above a 1 m mat.
constexpr int kTargetTexturePx = 1024;

// Two layers with incommensurate repeats and a rotation between them, so the
// pattern never visibly repeats; the shader's constant must match.
constexpr double kDetailRepeat1_m = 10.24;

// The second layer scales with the world's imagery: its coarsest clumps are
// one imagery texel, so coarse real imagery (30 m Landsat) also gets texture
// between its texel and the first layer's.
double detailRepeat2_m(const terrain::World& world) {
  return std::max(6.37, 32.0 * world.imageryResolution_m());
}
constexpr double kDetailAngle2_rad = 0.61;

// An 8-bit RGB image as a mipmapped, edge-clamped texture.
double positiveMod(double value, double period) {
  const double r = std::fmod(value, period);
  return r < 0.0 ? r + period : r;
}

Eigen::Matrix4d clipFromCamera(const CameraIntrinsics& k, double near_m, double far_m) {
  // Optical frame to clip space such that image row 0 lands on the framebuffer's
  // bottom row: glReadPixels then returns the image top row first.
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 2.0 * k.fx / k.width;
  P(0, 2) = 2.0 * (k.cx + 0.5) / k.width - 1.0;
  P(1, 1) = 2.0 * k.fy / k.height;
  P(1, 2) = 2.0 * (k.cy + 0.5) / k.height - 1.0;
  P(2, 2) = (far_m + near_m) / (far_m - near_m);
  P(2, 3) = -2.0 * far_m * near_m / (far_m - near_m);
  P(3, 2) = 1.0;
  return P;
}

// Clip space from a tile's frame (its corner origin_ned, world axes): camera-
// relative in double, then float, for full precision near the camera.
Eigen::Matrix4f clipFromTile(const Eigen::Matrix4d& clip_from_camera,
                             const Eigen::Isometry3d& T_world_cam,
                             const terrain::GroundSquare& square) {
  const Eigen::Matrix3d R_cam_world = T_world_cam.rotation().transpose();
  const Eigen::Vector3d origin_ned(square.north_min_m, square.east_min_m, 0.0);
  Eigen::Matrix4d camera_from_local = Eigen::Matrix4d::Identity();
  camera_from_local.topLeftCorner<3, 3>() = R_cam_world;
  camera_from_local.topRightCorner<3, 1>() = R_cam_world * (origin_ned - T_world_cam.translation());
  return (clip_from_camera * camera_from_local).cast<float>();
}

}  // namespace

struct TerrainRenderer::GpuTile {
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;
  GLuint texture = 0;
  std::size_t bytes = 0;
  terrain::GroundSquare square;
  std::list<std::uint64_t>::iterator lru_position;
  // The tile's trees and buildings, when objects_3d and its texel is fine enough.
  std::unique_ptr<ObjectInstances> objects;

  ~GpuTile() {
    glDeleteTextures(1, &texture);
    glDeleteBuffers(1, &vertex_buffer);
    glDeleteVertexArrays(1, &vertex_array);
  }
};

struct TerrainRenderer::GpuTarget {
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;
  GLuint texture = 0;
  Eigen::Vector3d centre_ned;

  ~GpuTarget() {
    glDeleteTextures(1, &texture);
    glDeleteBuffers(1, &vertex_buffer);
    glDeleteVertexArrays(1, &vertex_array);
  }
};

void TerrainRendererParams::visit(core::ParamVisitor& v) {
  v.field(
      "tile_cache_mib", &tile_cache_mib,
      {.doc = "memory for tile meshes and textures on the GL side, MiB", .min = 16, .max = 65536});
  v.field(
      "detail_contrast", &detail_contrast,
      {.doc = "contrast of the texture added below the imagery's resolution", .min = 0, .max = 1});
  v.field("objects_3d", &objects_3d,
          {.doc = "trees and buildings stand up as 3D objects with their heights"});
  v.field("objects_max_texel_m", &objects_max_texel_m,
          {.doc = "objects are drawn on tiles whose texel is at most this, m (farther: imagery "
                  "only)",
           .min = 0.01,
           .max = 1000});
  v.field("prefetch_tiles", &prefetch_tiles,
          {.doc = "make the imagery of tiles about to be seen on a worker thread (same pixels)"});
}

TerrainRenderer::TerrainRenderer(std::shared_ptr<terrain::TileTree> tiles,
                                 const TerrainRendererParams& params)
    : tiles_(std::move(tiles)), params_(params) {
  const std::string fragment_plain = std::string("#version 450 core\n") + kFragmentShader;
  const std::string fragment_detail =
      std::string("#version 450 core\n#define GROUND_DETAIL 1\n") + kFragmentShader;
  program_plain_ = linkProgram("terrain", kVertexShader, fragment_plain);
  program_detail_ = linkProgram("terrain+detail", kVertexShader, fragment_detail);
  program_target_ = linkProgram("ground target", kTargetVertexShader, kTargetFragmentShader);

  // One index buffer serves every tile: the grid, then a skirt down from each
  // edge that hides cracks between tiles of different levels.
  const int q = tiles_->params().mesh_quads;
  const int n = q + 1;
  std::vector<GLuint> indices;
  const auto grid = [n](int r, int c) { return static_cast<GLuint>(r * n + c); };
  for (int r = 0; r < q; ++r) {
    for (int c = 0; c < q; ++c) {
      indices.insert(indices.end(), {grid(r, c), grid(r, c + 1), grid(r + 1, c + 1), grid(r, c),
                                     grid(r + 1, c + 1), grid(r + 1, c)});
    }
  }
  const auto skirt = [n](int edge, int i) { return static_cast<GLuint>(n * n + edge * n + i); };
  for (int i = 0; i < q; ++i) {
    const GLuint edges[4][2] = {{grid(0, i), grid(0, i + 1)},
                                {grid(q, i), grid(q, i + 1)},
                                {grid(i, 0), grid(i + 1, 0)},
                                {grid(i, q), grid(i + 1, q)}};
    for (int edge = 0; edge < 4; ++edge) {
      indices.insert(indices.end(), {edges[edge][0], edges[edge][1], skirt(edge, i + 1),
                                     edges[edge][0], skirt(edge, i + 1), skirt(edge, i)});
    }
  }
  index_count_ = static_cast<int>(indices.size());
  glGenBuffers(1, &index_buffer_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)),
               indices.data(), GL_STATIC_DRAW);

  const cv::Mat detail = makeDetailTexture();
  glGenTextures(1, &detail_texture_);
  glBindTexture(GL_TEXTURE_2D, detail_texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, detail.cols, detail.rows, 0, GL_RED, GL_UNSIGNED_BYTE,
               detail.data);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  if (params_.objects_3d) objects_ = std::make_unique<GroundObjectRenderer>();
  if (params_.prefetch_tiles) {
    prefetcher_ = std::make_unique<terrain::TilePrefetcher>(tiles_, objectsMaxTexel_m());
  }
  checkGl("creating the terrain renderer");
}

TerrainRenderer::~TerrainRenderer() {
  gpu_tiles_.clear();
  targets_.clear();
  objects_.reset();
  boards_.reset();
  glDeleteProgram(program_target_);
  glDeleteTextures(1, &detail_texture_);
  glDeleteBuffers(1, &index_buffer_);
  glDeleteProgram(program_plain_);
  glDeleteProgram(program_detail_);
}

void TerrainRenderer::setTargets(const std::vector<terrain::GroundTarget>& targets) {
  targets_.clear();
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  for (const terrain::GroundTarget& target : targets) {
    auto gpu = std::make_unique<GpuTarget>();
    gpu->centre_ned = Eigen::Vector3d(target.north_m, target.east_m,
                                      -tiles_->world().groundUp_m(target.north_m, target.east_m));
    // Corners in texture order: (0,0) north-west, (1,0) north-east, (1,1), (0,1).
    const double c = std::cos(target.yaw_deg * kDeg), s = std::sin(target.yaw_deg * kDeg);
    const double half = 0.5 * target.size_m;
    std::vector<float> vertices;
    for (const auto& [u, v] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}}) {
      const double north_in_mat = half - v * target.size_m;
      const double east_in_mat = u * target.size_m - half;
      const double north = c * north_in_mat - s * east_in_mat;
      const double east = s * north_in_mat + c * east_in_mat;
      const double down = -tiles_->world().groundUp_m(target.north_m + north, target.east_m + east);
      vertices.insert(vertices.end(), {static_cast<float>(north), static_cast<float>(east),
                                       static_cast<float>(down - gpu->centre_ned.z()),
                                       static_cast<float>(u), static_cast<float>(v)});
    }
    glGenVertexArrays(1, &gpu->vertex_array);
    glBindVertexArray(gpu->vertex_array);
    glGenBuffers(1, &gpu->vertex_buffer);
    glBindBuffer(GL_ARRAY_BUFFER, gpu->vertex_buffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
                 vertices.data(), GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 5 * sizeof(float), nullptr);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 5 * sizeof(float),
                          reinterpret_cast<const void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(1);
    glBindVertexArray(0);
    gpu->texture =
        uploadRgbTexture(terrain::targetTexture(target, kTargetTexturePx), GL_LINEAR_MIPMAP_LINEAR);
    targets_.push_back(std::move(gpu));
  }
  checkGl("uploading ground targets");
}

void TerrainRenderer::setBoards(const std::vector<terrain::CourseBoard>& boards) {
  if (!boards_) boards_ = std::make_unique<CourseBoardRenderer>();
  boards_->setBoards(boards, tiles_->world());
}

void TerrainRenderer::drawTargets(const DrawView& view, const Eigen::Matrix4d& clip_from_camera) {
  if (targets_.empty()) return;
  // Mats lie on the ground; the mesh may sit a little above the true ground at
  // coarse levels, so they are drawn over the terrain without a depth test (a
  // downward camera never has terrain between itself and a mat on the ground).
  glDisable(GL_DEPTH_TEST);
  glUseProgram(program_target_);
  glUniform1f(glGetUniformLocation(program_target_, "u_gain"), static_cast<float>(view.gain));
  glUniform1i(glGetUniformLocation(program_target_, "u_gray"), view.gray ? 1 : 0);
  glUniform1i(glGetUniformLocation(program_target_, "u_texture"), 0);
  const GLint clip_from_local = glGetUniformLocation(program_target_, "u_clip_from_local");
  const Eigen::Matrix3d R_cam_world = view.T_world_cam.rotation().transpose();
  for (const auto& target : targets_) {
    Eigen::Matrix4d camera_from_local = Eigen::Matrix4d::Identity();
    camera_from_local.topLeftCorner<3, 3>() = R_cam_world;
    camera_from_local.topRightCorner<3, 1>() =
        R_cam_world * (target->centre_ned - view.T_world_cam.translation());
    // Behind the camera: nothing to draw (and the projection would mirror it).
    if (camera_from_local(2, 3) <= view.near_m) continue;
    const Eigen::Matrix4f clip = (clip_from_camera * camera_from_local).cast<float>();
    glUniformMatrix4fv(clip_from_local, 1, GL_FALSE, clip.data());
    glBindTexture(GL_TEXTURE_2D, target->texture);
    glBindVertexArray(target->vertex_array);
    glDrawArrays(GL_TRIANGLE_FAN, 0, 4);
  }
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
}

void TerrainRenderer::drawObjects(const DrawView& view, const Eigen::Matrix4d& clip_from_camera,
                                  const std::vector<terrain::TileId>& visible,
                                  const std::vector<double>& nearest_m, DrawStats& stats) {
  const double focal_px = std::max(view.intrinsics.fx, view.intrinsics.fy);
  objects_->begin(tiles_->world().sunDirectionNed(), view.gain, view.gray);
  for (std::size_t i = 0; i < visible.size(); ++i) {
    const auto found = gpu_tiles_.find(visible[i].key());
    if (found == gpu_tiles_.end() || !found->second->objects) continue;
    const GpuTile& tile = *found->second;
    // Fine meshes while a 4 m crown at the tile's nearest point spans 16 px or more.
    const ObjectDetail detail = 4.0 * focal_px / std::max(nearest_m[i], 1.0) >= 16.0
                                    ? ObjectDetail::kFine
                                    : ObjectDetail::kCoarse;
    const Eigen::Matrix4f clip = clipFromTile(clip_from_camera, view.T_world_cam, tile.square);
    const ObjectDrawStats drawn = objects_->draw(*tile.objects, clip.data(), detail);
    stats.objects += drawn.objects;
    stats.triangles += drawn.triangles;
  }
  objects_->end();
}

terrain::LodView lodViewOf(const DrawView& view) {
  terrain::LodView lod;
  lod.camera_ned = view.T_world_cam.translation();
  lod.focal_px = std::max(view.intrinsics.fx, view.intrinsics.fy);
  const Eigen::Matrix3d R_world_cam = view.T_world_cam.rotation();
  const CameraIntrinsics& k = view.intrinsics;
  // Side planes through the camera centre and the image's outer pixel edges.
  const double left = (-0.5 - k.cx) / k.fx, right = (k.width - 0.5 - k.cx) / k.fx;
  const double top = (-0.5 - k.cy) / k.fy, bottom = (k.height - 0.5 - k.cy) / k.fy;
  const Eigen::Vector3d normals_cam[4] = {Eigen::Vector3d(1.0, 0.0, -left).normalized(),
                                          Eigen::Vector3d(-1.0, 0.0, right).normalized(),
                                          Eigen::Vector3d(0.0, 1.0, -top).normalized(),
                                          Eigen::Vector3d(0.0, -1.0, bottom).normalized()};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d n = R_world_cam * normals_cam[i];
    lod.frustum_planes[static_cast<std::size_t>(i)] << n, -n.dot(lod.camera_ned);
  }
  const Eigen::Vector3d forward = R_world_cam.col(2);
  lod.frustum_planes[4] << forward, -forward.dot(lod.camera_ned) - view.near_m;
  lod.frustum_planes[5] << -forward, forward.dot(lod.camera_ned) + view.far_m;
  return lod;
}

std::vector<terrain::TileId> TerrainRenderer::visibleTiles(const DrawView& view) {
  return tiles_->select(lodViewOf(view));
}

void TerrainRenderer::expect(const std::vector<DrawView>& views) {
  if (!prefetcher_) return;
  std::vector<terrain::LodView> lod_views;
  lod_views.reserve(views.size());
  for (const DrawView& view : views) lod_views.push_back(lodViewOf(view));
  prefetcher_->expect(std::move(lod_views));
}

TerrainRenderer::GpuTile& TerrainRenderer::acquire(const terrain::TileId& id, int& uploaded) {
  const std::uint64_t key = id.key();
  const auto found = gpu_tiles_.find(key);
  if (found != gpu_tiles_.end()) {
    lru_.splice(lru_.begin(), lru_, found->second->lru_position);
    return *found->second;
  }
  const core::ScopedStage stage("new tile");
  const std::shared_ptr<const terrain::TileGeometry> geometry = tiles_->geometry(id);
  const int n = geometry->vertices_per_edge;
  const int q = n - 1;
  const double step_m = geometry->square.size_m / q;
  // Skirts reach below the mesh by more than the error of any neighbour's level.
  const float skirt_m = static_cast<float>(
      std::max(2.0 * geometry->geometric_error_m, 0.02 * geometry->square.size_m));
  std::vector<float> vertices;
  vertices.reserve(static_cast<std::size_t>(n * n + 4 * n) * 3);
  const auto vertex = [&](int r, int c, float extra_down_m) {
    vertices.push_back(static_cast<float>(r * step_m));
    vertices.push_back(static_cast<float>(c * step_m));
    vertices.push_back(-geometry->height_up_m[static_cast<std::size_t>(r) * n + c] + extra_down_m);
  };
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) vertex(r, c, 0.0f);
  }
  for (int i = 0; i < n; ++i) vertex(0, i, skirt_m);
  for (int i = 0; i < n; ++i) vertex(q, i, skirt_m);
  for (int i = 0; i < n; ++i) vertex(i, 0, skirt_m);
  for (int i = 0; i < n; ++i) vertex(i, q, skirt_m);

  auto tile = std::make_unique<GpuTile>();
  tile->square = geometry->square;
  glGenVertexArrays(1, &tile->vertex_array);
  glBindVertexArray(tile->vertex_array);
  glGenBuffers(1, &tile->vertex_buffer);
  glBindBuffer(GL_ARRAY_BUFFER, tile->vertex_buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
               vertices.data(), GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glEnableVertexAttribArray(0);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_);
  glBindVertexArray(0);

  // Where the objects stand up, the imagery leaves out their tops.
  const bool objects = tiles_->beneathObjects(id, objectsMaxTexel_m());
  cv::Mat rgb;
  {
    const core::ScopedStage imagery_stage("imagery");
    rgb = prefetcher_ ? prefetcher_->take(id) : tiles_->imagery(id, objects);
  }
  {
    // Nearest mip level, bilinear within it: cheaper than trilinear on llvmpipe,
    // and the tile choice keeps the level near 0 (a texel about a pixel).
    const core::ScopedStage upload_stage("upload");
    tile->texture = uploadRgbTexture(rgb, GL_LINEAR_MIPMAP_NEAREST);
  }
  tile->bytes =
      vertices.size() * sizeof(float) + static_cast<std::size_t>(rgb.cols) * rgb.rows * 4 * 4 / 3;
  if (objects) {
    tile->objects = std::make_unique<ObjectInstances>(
        tiles_->world().objects(tile->square),
        Eigen::Vector3d(tile->square.north_min_m, tile->square.east_min_m, 0.0));
    tile->bytes += tile->objects->bytes();
  }
  gpu_bytes_ += tile->bytes;
  lru_.push_front(key);
  tile->lru_position = lru_.begin();
  ++uploaded;
  return *gpu_tiles_.emplace(key, std::move(tile)).first->second;
}

void TerrainRenderer::evictBeyondBudget(const std::vector<terrain::TileId>& in_use) {
  const auto budget = static_cast<std::size_t>(params_.tile_cache_mib * 1024 * 1024);
  // The least recently used tiles go first; never one the current frame drew.
  while (gpu_bytes_ > budget && lru_.size() > in_use.size()) {
    const std::uint64_t key = lru_.back();
    lru_.pop_back();
    if (prefetcher_) prefetcher_->released(key);
    const auto it = gpu_tiles_.find(key);
    gpu_bytes_ -= it->second->bytes;
    gpu_tiles_.erase(it);
  }
}

DrawStats TerrainRenderer::draw(const DrawView& view) {
  DrawStats stats;
  std::vector<terrain::TileId> visible;
  {
    const core::ScopedStage stage("select tiles");
    visible = visibleTiles(view);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glClearColor(0.5f, 0.5f, 0.5f, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, detail_texture_);
  glActiveTexture(GL_TEXTURE0);

  // Detail fades in only where a pixel is finer than the tile's texel. A pixel
  // is never finer than (nearest distance) / focal, so tiles whose texel is at
  // most that take the plain program and give the same pixels for less work.
  const Eigen::Vector3d camera_ned = view.T_world_cam.translation();
  const double focal_px = std::max(view.intrinsics.fx, view.intrinsics.fy);
  std::vector<terrain::TileId> plain, detailed;
  std::vector<double> nearest_m;  // per visible tile
  nearest_m.reserve(visible.size());
  for (const terrain::TileId& id : visible) {
    const auto geometry = tiles_->geometry(id);
    const terrain::GroundSquare& sq = geometry->square;
    nearest_m.push_back(geometry->distanceFrom_m(camera_ned));
    const double texel_m = sq.size_m / tiles_->params().texture_px;
    (view.ground_detail && texel_m > nearest_m.back() / focal_px ? detailed : plain).push_back(id);
  }

  const Eigen::Matrix4d P = clipFromCamera(view.intrinsics, view.near_m, view.far_m);
  for (const auto& [program, ids] :
       {std::pair{program_plain_, &plain}, {program_detail_, &detailed}}) {
    if (ids->empty()) continue;
    glUseProgram(program);
    const GLint clip_from_local = glGetUniformLocation(program, "u_clip_from_local");
    const GLint size_m = glGetUniformLocation(program, "u_size_m");
    const GLint texel_m = glGetUniformLocation(program, "u_texel_m");
    const GLint detail_origin_1 = glGetUniformLocation(program, "u_detail_origin_1");
    const GLint detail_origin_2 = glGetUniformLocation(program, "u_detail_origin_2");
    glUniform1f(glGetUniformLocation(program, "u_texture_px"),
                static_cast<float>(tiles_->params().texture_px));
    glUniform1f(glGetUniformLocation(program, "u_gain"), static_cast<float>(view.gain));
    glUniform1f(glGetUniformLocation(program, "u_detail_contrast"),
                static_cast<float>(params_.detail_contrast));
    glUniform1i(glGetUniformLocation(program, "u_gray"), view.gray ? 1 : 0);
    glUniform1i(glGetUniformLocation(program, "u_imagery"), 0);
    glUniform1i(glGetUniformLocation(program, "u_detail"), 1);
    const float c2 = static_cast<float>(std::cos(kDetailAngle2_rad));
    const float s2 = static_cast<float>(std::sin(kDetailAngle2_rad));
    const float rotation_2[4] = {c2, s2, -s2, c2};  // column-major
    glUniformMatrix2fv(glGetUniformLocation(program, "u_detail_rotation_2"), 1, GL_FALSE,
                       rotation_2);
    const double repeat_2_m = detailRepeat2_m(tiles_->world());
    glUniform1f(glGetUniformLocation(program, "u_detail_repeat_2_m"),
                static_cast<float>(repeat_2_m));
    for (const terrain::TileId& id : *ids) {
      GpuTile& tile = acquire(id, stats.tiles_uploaded);
      const Eigen::Matrix4f clip = clipFromTile(P, view.T_world_cam, tile.square);
      glUniformMatrix4fv(clip_from_local, 1, GL_FALSE, clip.data());
      glUniform1f(size_m, static_cast<float>(tile.square.size_m));
      glUniform1f(texel_m, static_cast<float>(tile.square.size_m / tiles_->params().texture_px));
      const double east = tile.square.east_min_m, north = tile.square.north_min_m;
      glUniform2f(detail_origin_1, static_cast<float>(positiveMod(east, kDetailRepeat1_m)),
                  static_cast<float>(positiveMod(north, kDetailRepeat1_m)));
      const double c = std::cos(kDetailAngle2_rad), s = std::sin(kDetailAngle2_rad);
      glUniform2f(detail_origin_2,
                  static_cast<float>(positiveMod(c * east - s * north, repeat_2_m)),
                  static_cast<float>(positiveMod(s * east + c * north, repeat_2_m)));
      glBindTexture(GL_TEXTURE_2D, tile.texture);
      glBindVertexArray(tile.vertex_array);
      glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
      ++stats.tiles;
      stats.triangles += index_count_ / 3;
    }
  }
  glBindVertexArray(0);
  if (objects_) drawObjects(view, P, visible, nearest_m, stats);
  drawTargets(view, P);
  if (boards_) stats.boards = boards_->draw(P, view.T_world_cam, view.near_m, view.gain, view.gray);
  evictBeyondBudget(visible);
  checkGl("drawing the terrain");
  return stats;
}

}  // namespace nadir::render
