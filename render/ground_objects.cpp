#include "render/ground_objects.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "render/gl.h"

namespace nadir::render {
namespace {

// Meshes in a unit frame: x along the object's long axis (north at heading
// 0), y to its right (east), z up from the ground, scaled per instance by
// (half length, half width, height). Each vertex: position, normal (in the
// unit frame; the shader applies the inverse scale).
constexpr int kVertexFloats = 6;

// Per instance: position of the base (NED, tile-local), the scale, the
// heading (cos, sin), the unlit colour (0-1).
constexpr int kInstanceFloats = 11;

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 unit_position;
layout(location = 1) in vec3 unit_normal;
layout(location = 2) in vec3 base_ned;
layout(location = 3) in vec3 scale;
layout(location = 4) in vec2 heading;
layout(location = 5) in vec3 colour;
uniform mat4 u_clip_from_local;
out vec3 v_normal_ned;
out vec3 v_colour;
vec3 toNed(vec3 v) {
  // Unit frame (along, right, up) to NED, turned by the heading.
  return vec3(heading.x * v.x - heading.y * v.y, heading.y * v.x + heading.x * v.y, -v.z);
}
void main() {
  vec3 local = base_ned + toNed(unit_position * scale);
  gl_Position = u_clip_from_local * vec4(local, 1.0);
  v_normal_ned = toNed(unit_normal / scale);
  v_colour = colour;
}
)";

constexpr const char* kFragmentShader = R"(#version 450 core
in vec3 v_normal_ned;
in vec3 v_colour;
uniform vec3 u_sun_ned;
uniform float u_gain;
uniform bool u_gray;
out vec4 out_colour;
void main() {
  // The imagery's law for crowns (terrain/procedural/forests.cpp): skylight
  // and Lambert's, 0.97 of the colour on a level top under a 45 deg sun.
  float lit = 0.62 + 0.5 * max(dot(normalize(v_normal_ned), u_sun_ned), 0.0);
  vec3 c = v_colour * lit * u_gain;
  out_colour = u_gray ? vec4(dot(c, vec3(0.299, 0.587, 0.114)), 0.0, 0.0, 1.0) : vec4(c, 1.0);
}
)";

using Vertices = std::vector<float>;

void addVertex(Vertices& v, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  v.insert(v.end(),
           {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()),
            static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())});
}

// A flat triangle, counter-clockwise seen from outside.
void addFace(Vertices& v, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  addVertex(v, a, n);
  addVertex(v, b, n);
  addVertex(v, c, n);
}

void addQuad(Vertices& v, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  addFace(v, a, b, c);
  addFace(v, a, c, d);
}

Eigen::Vector3d ring(int i, int segments, double radius, double z) {
  const double t = 2.0 * std::numbers::pi * i / segments;
  return {radius * std::cos(t), radius * std::sin(t), z};
}

// The polygon of n sides whose area is the unit disc's: its corners' radius.
double sameAreaRadius(int n) {
  return std::sqrt(std::numbers::pi / (0.5 * n * std::sin(2.0 * std::numbers::pi / n)));
}

// An upright prism (a trunk) of radius r from z0 to z1.
void addPrism(Vertices& v, int segments, double r, double z0, double z1) {
  for (int i = 0; i < segments; ++i) {
    addQuad(v, ring(i, segments, r, z0), ring(i + 1, segments, r, z0), ring(i + 1, segments, r, z1),
            ring(i, segments, r, z1));
  }
}

// An ellipsoid crown: radius 1 across (its widest polygon as large as the
// unit disc), from z0 to z1, smooth normals.
void addCrown(Vertices& v, int segments, int stacks, double z0, double z1) {
  const double centre = 0.5 * (z0 + z1), half = 0.5 * (z1 - z0);
  const double across = sameAreaRadius(segments);
  const auto point = [&](int i, int k) {
    const double phi = std::numbers::pi * k / stacks;  // 0 at the top
    const double t = 2.0 * std::numbers::pi * i / segments;
    const Eigen::Vector3d unit(std::sin(phi) * std::cos(t), std::sin(phi) * std::sin(t),
                               std::cos(phi));
    return std::pair{
        Eigen::Vector3d(across * unit.x(), across * unit.y(), centre + half * unit.z()),
        Eigen::Vector3d(unit.x(), unit.y(), unit.z() / half)};
  };
  const auto emit = [&](const std::pair<Eigen::Vector3d, Eigen::Vector3d>& p) {
    addVertex(v, p.first, p.second.normalized());
  };
  for (int k = 0; k < stacks; ++k) {
    for (int i = 0; i < segments; ++i) {
      const auto a = point(i, k), b = point(i, k + 1), c = point(i + 1, k + 1), d = point(i + 1, k);
      // At the poles a quad is one triangle (a = d at the top, b = c at the bottom).
      if (k + 1 < stacks) {
        emit(a), emit(b), emit(c);
      }
      if (k > 0) {
        emit(a), emit(k + 1 < stacks ? c : b), emit(d);
      }
    }
  }
}

// A cone (a conifer's crown): its base as large as the unit disc at z0, its
// apex at z1.
void addCone(Vertices& v, int segments, double z0, double z1) {
  const Eigen::Vector3d apex(0.0, 0.0, z1);
  const double r = sameAreaRadius(segments);
  for (int i = 0; i < segments; ++i) {
    addFace(v, ring(i, segments, r, z0), ring(i + 1, segments, r, z0), apex);
    addFace(v, ring(i + 1, segments, r, z0), ring(i, segments, r, z0),
            Eigen::Vector3d(0.0, 0.0, z0));
  }
}

// Walls from the ground to z_eave over the footprint [-1, 1] x [-1, 1], and
// a flat roof at z_eave (gable false) or a ridge along x at z = 1.
void addBuilding(Vertices& v, bool gable) {
  const double eave = gable ? 0.7 : 1.0;
  const Eigen::Vector3d c[4] = {{1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}};
  const Eigen::Vector3d up_eave(0, 0, eave);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d& a = c[i];
    const Eigen::Vector3d& b = c[(i + 1) % 4];
    addQuad(v, a, b, b + up_eave, a + up_eave);
  }
  if (!gable) {
    addQuad(v, c[3] + up_eave, c[2] + up_eave, c[1] + up_eave, c[0] + up_eave);
    return;
  }
  const Eigen::Vector3d ridge_front(1, 0, 1), ridge_back(-1, 0, 1);
  // The two roof slopes and the gable ends.
  addQuad(v, c[3] + up_eave, c[0] + up_eave, ridge_front, ridge_back);
  addQuad(v, c[1] + up_eave, c[2] + up_eave, ridge_back, ridge_front);
  addFace(v, c[0] + up_eave, c[1] + up_eave, ridge_front);
  addFace(v, c[2] + up_eave, c[3] + up_eave, ridge_back);
}

Vertices broadleafMesh(ObjectDetail detail) {
  Vertices v;
  // The crown spans the top 55 % of the height; the trunk below it.
  if (detail == ObjectDetail::kFine) {
    addPrism(v, 5, 0.08, 0.0, 0.5);
    addCrown(v, 8, 4, 0.45, 1.0);
  } else {
    addCrown(v, 6, 2, 0.45, 1.0);
  }
  return v;
}

Vertices coniferMesh(ObjectDetail detail) {
  Vertices v;
  if (detail == ObjectDetail::kFine) {
    addPrism(v, 4, 0.1, 0.0, 0.2);
    addCone(v, 8, 0.2, 1.0);
  } else {
    addCone(v, 6, 0.2, 1.0);
  }
  return v;
}

Vertices buildingMesh(bool gable) {
  Vertices v;
  addBuilding(v, gable);
  return v;
}

// The mesh index of an object kind (order of GroundObjectRenderer::meshes_).
int meshIndex(const terrain::GroundObject& o) {
  switch (o.kind) {
    case terrain::GroundObject::Kind::kBroadleaf:
      return 0;
    case terrain::GroundObject::Kind::kConifer:
      return 1;
    case terrain::GroundObject::Kind::kBuilding:
      break;
  }
  return o.gable ? 3 : 2;
}

}  // namespace

ObjectInstances::ObjectInstances(const std::vector<terrain::GroundObject>& objects,
                                 const Eigen::Vector3d& origin_ned) {
  std::array<std::vector<float>, 4> by_mesh;
  for (const terrain::GroundObject& o : objects) {
    std::vector<float>& data = by_mesh[static_cast<std::size_t>(meshIndex(o))];
    const bool tree = o.kind != terrain::GroundObject::Kind::kBuilding;
    data.insert(
        data.end(),
        {static_cast<float>(o.north_m - origin_ned.x()),
         static_cast<float>(o.east_m - origin_ned.y()),
         static_cast<float>(-o.base_up_m - origin_ned.z()), static_cast<float>(o.half_length_m),
         static_cast<float>(tree ? o.half_length_m : o.half_width_m),
         static_cast<float>(o.height_m), static_cast<float>(std::cos(o.heading_rad)),
         static_cast<float>(std::sin(o.heading_rad)), o.rgb[0] / 255.0f, o.rgb[1] / 255.0f,
         o.rgb[2] / 255.0f});
  }
  std::vector<float> all;
  for (std::size_t k = 0; k < by_mesh.size(); ++k) {
    first_[k] = static_cast<int>(all.size() / kInstanceFloats);
    count_of_[k] = static_cast<int>(by_mesh[k].size() / kInstanceFloats);
    all.insert(all.end(), by_mesh[k].begin(), by_mesh[k].end());
  }
  count_ = objects.size();
  bytes_ = all.size() * sizeof(float);
  if (all.empty()) return;
  glCreateBuffers(1, &buffer_);
  glNamedBufferStorage(buffer_, static_cast<GLsizeiptr>(bytes_), all.data(), 0);
}

ObjectInstances::~ObjectInstances() {
  if (buffer_ != 0) glDeleteBuffers(1, &buffer_);
}

GroundObjectRenderer::Mesh GroundObjectRenderer::makeMesh(const std::vector<float>& vertices) {
  Mesh mesh;
  mesh.vertices = static_cast<int>(vertices.size() / kVertexFloats);
  glCreateBuffers(1, &mesh.vertex_buffer);
  glNamedBufferStorage(mesh.vertex_buffer, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
                       vertices.data(), 0);
  glCreateVertexArrays(1, &mesh.vertex_array);
  const GLuint vao = mesh.vertex_array;
  glVertexArrayVertexBuffer(vao, 0, mesh.vertex_buffer, 0, kVertexFloats * sizeof(float));
  for (GLuint a = 0; a < 2; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
    glVertexArrayAttribBinding(vao, a, 0);
  }
  // Binding 1: the instances, bound per tile.
  const GLint sizes[4] = {3, 3, 2, 3};
  GLuint offset = 0;
  for (GLuint a = 2; a < 6; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, sizes[a - 2], GL_FLOAT, GL_FALSE, offset * sizeof(float));
    glVertexArrayAttribBinding(vao, a, 1);
    offset += static_cast<GLuint>(sizes[a - 2]);
  }
  glVertexArrayBindingDivisor(vao, 1, 1);
  return mesh;
}

GroundObjectRenderer::GroundObjectRenderer() {
  program_ = linkProgram("ground objects", kVertexShader, kFragmentShader);
  clip_from_local_ = glGetUniformLocation(program_, "u_clip_from_local");
  for (const ObjectDetail detail : {ObjectDetail::kCoarse, ObjectDetail::kFine}) {
    const auto d = static_cast<std::size_t>(detail);
    meshes_[0][d] = makeMesh(broadleafMesh(detail));
    meshes_[1][d] = makeMesh(coniferMesh(detail));
    meshes_[2][d] = makeMesh(buildingMesh(false));
    meshes_[3][d] = makeMesh(buildingMesh(true));
  }
  checkGl("creating the ground objects' meshes");
}

GroundObjectRenderer::~GroundObjectRenderer() {
  for (auto& kind : meshes_) {
    for (Mesh& mesh : kind) {
      glDeleteVertexArrays(1, &mesh.vertex_array);
      glDeleteBuffers(1, &mesh.vertex_buffer);
    }
  }
  glDeleteProgram(program_);
}

void GroundObjectRenderer::begin(const std::array<double, 3>& sun_ned, double gain, bool gray) {
  glUseProgram(program_);
  glUniform3f(glGetUniformLocation(program_, "u_sun_ned"), static_cast<float>(sun_ned[0]),
              static_cast<float>(sun_ned[1]), static_cast<float>(sun_ned[2]));
  glUniform1f(glGetUniformLocation(program_, "u_gain"), static_cast<float>(gain));
  glUniform1i(glGetUniformLocation(program_, "u_gray"), gray ? 1 : 0);
}

ObjectDrawStats GroundObjectRenderer::draw(const ObjectInstances& instances,
                                           const float* clip_from_local_4x4, ObjectDetail detail) {
  ObjectDrawStats stats;
  if (instances.buffer_ == 0) return stats;
  glUniformMatrix4fv(clip_from_local_, 1, GL_FALSE, clip_from_local_4x4);
  for (std::size_t k = 0; k < meshes_.size(); ++k) {
    if (instances.count_of_[k] == 0) continue;
    const Mesh& mesh = meshes_[k][static_cast<std::size_t>(detail)];
    glBindVertexArray(mesh.vertex_array);
    glVertexArrayVertexBuffer(mesh.vertex_array, 1, instances.buffer_, 0,
                              kInstanceFloats * sizeof(float));
    glDrawArraysInstancedBaseInstance(GL_TRIANGLES, 0, mesh.vertices, instances.count_of_[k],
                                      static_cast<GLuint>(instances.first_[k]));
    stats.objects += instances.count_of_[k];
    stats.triangles += instances.count_of_[k] * mesh.vertices / 3;
  }
  return stats;
}

void GroundObjectRenderer::end() { glBindVertexArray(0); }

}  // namespace nadir::render
