#include "msim/scene/schema/shape_schema.hpp"

namespace msim::scene {

Schema shapeSchema(std::string description) {
  const std::vector<int> twoOrThree{2, 3};

  Schema sphere = Schema::object("ball (circle in 2D)");
  sphere.vector("center", "m", 3, "centre").lengths(twoOrThree);
  sphere.number("radius", "m", "radius").min(0, Bound::Exclusive);

  Schema box = Schema::object("axis-aligned box (rectangle in 2D)");
  box.vector("min", "m", 3, "lower corner").lengths(twoOrThree);
  box.vector("max", "m", 3, "upper corner").lengths(twoOrThree);

  Schema capsule = Schema::object("all points within radius of the segment a-b");
  capsule.vector("a", "m", 3, "first end of the axis segment").lengths(twoOrThree);
  capsule.vector("b", "m", 3, "second end of the axis segment").lengths(twoOrThree);
  capsule.number("radius", "m", "radius around the segment").min(0, Bound::Exclusive);

  Schema plane = Schema::object("half-space behind a plane");
  plane.vector("point", "m", 3, "a point on the plane").lengths(twoOrThree);
  plane.vector("normal", "", 3, "outward normal; the solid is on the other side").lengths(twoOrThree);

  Schema mesh = Schema::object("closed triangle mesh");
  mesh.string("file", "mesh file (.obj or .ply), relative to the scene file");
  mesh.number("scale", "", 1.0, "uniform scale applied to the mesh vertices").min(0, Bound::Exclusive);
  mesh.vector("translate", "m", {0.0, 0.0, 0.0}, "translation applied after scaling");

  Schema shape = Schema::variant(std::move(description));
  shape.alternative("sphere", std::move(sphere))
      .alternative("box", std::move(box))
      .alternative("capsule", std::move(capsule))
      .alternative("plane", std::move(plane))
      .alternative("mesh", std::move(mesh));
  return shape;
}

}  // namespace msim::scene
