// How an entity shows in ROS: the tf frame it is published under and the
// colour its markers take when its request gave none.
#pragma once

#include "sphere_tree_collision/scene/entity_request.hpp"

#include <string>

namespace stc_ros {

using stc::Rgba;

// Frame of an entity: its name when it has one, else "entity_<id>"
// (stc::validateEntityName keeps names out of that form).
std::string entityFrame(stc::EntityId id, const std::string& name);

// Distinct colours for entities without one (golden-ratio hue steps).
Rgba paletteColor(stc::EntityId id);

}  // namespace stc_ros
