#pragma once
// Trees and buildings standing on the terrain (terrain::GroundObject), drawn
// as instanced low-polygon meshes: one instance buffer per tile, two levels
// of detail for trees. Needs a current OpenGL 4.5 core context.

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "terrain/world.h"

namespace nadir::render {

// The meshes a tile's objects are drawn with.
enum class ObjectDetail { kCoarse, kFine };

// One tile's objects on the GL side, grouped by mesh.
class ObjectInstances {
 public:
  // Positions relative to origin_ned (the tile's corner).
  ObjectInstances(const std::vector<terrain::GroundObject>& objects,
                  const Eigen::Vector3d& origin_ned);
  ~ObjectInstances();
  ObjectInstances(const ObjectInstances&) = delete;
  ObjectInstances& operator=(const ObjectInstances&) = delete;

  std::size_t bytes() const { return bytes_; }
  std::size_t count() const { return count_; }

 private:
  friend class GroundObjectRenderer;
  unsigned int buffer_ = 0;
  // First instance and count of each mesh kind, in the order of kKinds.
  std::array<int, 4> first_{}, count_of_{};
  std::size_t count_ = 0;
  std::size_t bytes_ = 0;
};

struct ObjectDrawStats {
  int objects = 0;
  int triangles = 0;
};

class GroundObjectRenderer {
 public:
  GroundObjectRenderer();
  ~GroundObjectRenderer();
  GroundObjectRenderer(const GroundObjectRenderer&) = delete;
  GroundObjectRenderer& operator=(const GroundObjectRenderer&) = delete;

  // Sets the program's per-view state: the light (unit vector towards the
  // sun, NED), the gain and whether luminance goes to the red channel.
  void begin(const std::array<double, 3>& sun_ned, double gain, bool gray);
  // Draws one tile's objects; clip_from_local maps the tile's local frame.
  ObjectDrawStats draw(const ObjectInstances& instances, const float* clip_from_local_4x4,
                       ObjectDetail detail);
  void end();

 private:
  struct Mesh {
    unsigned int vertex_array = 0;
    unsigned int vertex_buffer = 0;
    int vertices = 0;
  };
  Mesh makeMesh(const std::vector<float>& vertices);
  // [kind][detail]: broadleaf, conifer, flat-roofed and gable-roofed buildings.
  std::array<std::array<Mesh, 2>, 4> meshes_{};
  unsigned int program_ = 0;
  int clip_from_local_ = -1;
};

}  // namespace nadir::render
