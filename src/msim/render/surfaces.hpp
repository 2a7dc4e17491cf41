#pragma once
// Opaque surfaces the volume renderer draws with the medium: triangle meshes (cloth, obstacles,
// rigid bodies, liquid surfaces) and point sets drawn as small spheres (sand grains, agents,
// particles), gathered into one BVH for the camera rays and the shadow rays. (Obstacles saved as a
// signed-distance grid are traced in volume_renderer.cpp against the grid itself.) The surfaces are
// Lambertian (diffuse) reflectors; how they are lit is in volume_renderer.hpp.
#include <vector>

#include "msim/core/triangle_mesh.hpp"
#include "msim/numerics/bvh.hpp"
#include "msim/render/camera.hpp"

namespace msim::render {

// Spheres of one radius at the given positions: sand grains, agents, particles (Particles<3>
// positions). The vectors must outlive the render.
struct PointSet {
  const std::vector<Vecf<3>>* positions = nullptr;
  double radius = 0.0;                              // [m], > 0
  const std::vector<Vecf<3>>* colours = nullptr;    // optional per-point albedo (linear RGB in [0, 1])
  Vec3 albedo = Vec3::Constant(0.6);                // for every point when there are no colours

  // std::invalid_argument: no positions, a radius that is not positive, colours of another count,
  // an albedo outside [0, 1].
  void validate() const;
};

struct SurfaceHit {
  double t = 0.0;
  Vec3 normal = Vec3::Zero();  // unit shading normal, on the side the ray came from
  Vec3 offsetNormal = Vec3::Zero();  // unit geometric normal on that side, for offsetting shadow rays
  Vec3 albedo = Vec3::Zero();
};

class SurfaceScene {
 public:
  // Meshes are drawn with meshAlbedo and smooth normals (area-weighted vertex normals interpolated
  // across each triangle), seen from both sides. std::invalid_argument for a triangle indexing past
  // its mesh's vertices, non-finite vertices or an invalid point set.
  SurfaceScene(const std::vector<const TriangleMesh*>& meshes, const std::vector<PointSet>& points,
               const Vec3& meshAlbedo);

  bool empty() const { return bvh_.empty(); }
  // The nearest hit with t in (0, tMax).
  bool intersect(const Ray& ray, double tMax, SurfaceHit& hit) const;
  // Whether anything lies on origin + t dir for t in (0, tMax) (dir unit length).
  bool occluded(const Vec3& origin, const Vec3& dir, double tMax) const;

 private:
  struct Primitive {
    int set;    // mesh or point set
    int index;  // triangle or point
    bool sphere;
  };
  bool hitPrimitive(const Primitive& p, const Vec3& o, const Vec3& d, double& tMax, SurfaceHit* hit) const;

  std::vector<const TriangleMesh*> meshes_;
  std::vector<std::vector<Vec3>> vertexNormals_;  // per mesh
  std::vector<PointSet> points_;
  Vec3 meshAlbedo_;
  std::vector<Primitive> primitives_;
  numerics::Bvh bvh_;
};

// Index of the first mesh that encloses x, -1 if none: a ray from x crosses a closed surface an odd
// number of times (`crossings` receives that count). Brute force over the triangles: it runs once
// per render.
int meshContaining(const std::vector<const TriangleMesh*>& meshes, const Vec3& x, int* crossings = nullptr);

}  // namespace msim::render
