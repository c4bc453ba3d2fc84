#pragma once
// What the nadir-nav process takes: the filter's scenario group and, for the
// rangefinder against the map, the scenario's world (its registry entry fills
// both from a scenario).

#include <memory>

#include "core/params.h"
#include "nodes/nav/nav_node.h"
#include "terrain/world.h"
#include "terrain/world_factory.h"

namespace nadir::nav {

struct NavProcessParams {
  NavNodeParams node;
  terrain::WorldParams world;

  void visit(core::ParamVisitor& v) {
    node.visit(v);
    core::visitGroup(v, "world", "the world whose ground the rangefinder is taken against", world);
  }
};

// The map's ground under a north, east, built from the world, when the filter
// takes the rangefinder against it; else none. Throws what terrain::makeWorld throws.
inline GroundDown groundDownOf(const NavProcessParams& params) {
  if (!params.node.range_against_map) return {};
  std::shared_ptr<const terrain::World> world = terrain::makeWorld(params.world).world;
  return [world](double north_m, double east_m) { return -world->groundUp_m(north_m, east_m); };
}

}  // namespace nadir::nav
