#pragma once
// A small scene schema exercising every node kind, shared by the scene_schema tests.
#include "msim/scene/schema/schema.hpp"
#include "msim/scene/schema/shape_schema.hpp"

namespace msim::scene::testing {

inline Schema sampleSchema() {
  Schema domain = Schema::object("simulation domain");
  domain.vector("min", "m", {0.0, 0.0, 0.0}, "lower corner");
  domain.vector("max", "m", {1.0, 1.0, 1.0}, "upper corner");
  domain.integer("resolution", 64, "cells along the longest axis").min(1);
  domain.string("boundary", "open", "boundary condition").choices({"open", "closed"});

  Schema source = Schema::object("gas emitter");
  source.field("shape", shapeSchema("emitting region"));
  source.number("rate", "kg/m^3/s", 1.0, "density emitted per second").min(0);
  source.number("temperature", "K", 300.0, "temperature of emitted gas").min(0, Bound::Exclusive);

  Schema root = Schema::object("scene");
  root.string("name", "scene name");
  root.field("domain", std::move(domain));
  root.number("dissipation", "1/s", 0.0, "density decay rate").min(0).max(10);
  root.boolean("preview", true, "write preview images");
  root.array("sources", std::move(source), "gas emitters").items(0, 4);
  return root;
}

}  // namespace msim::scene::testing
