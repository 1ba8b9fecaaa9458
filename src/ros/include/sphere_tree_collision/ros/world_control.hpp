// WorldControl: what the node's services may ask of the node that owns the
// World. WorldNode implements it; WorldServices sees only this, so the
// services and the node's callbacks do not include each other. Each call is
// made on the node's spinner, between ticks.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <sphere_tree_collision/SpawnEntity.h>

#include <cstdint>
#include <string>

namespace stc_ros {

class WorldControl {
 public:
  virtual ~WorldControl() = default;
  virtual const std::string& worldFrame() const = 0;
  // Throws stc::InputError naming the field; nothing changes then.
  virtual stc::EntityId spawnEntity(const sphere_tree_collision::SpawnEntity& msg) = 0;  // pose in worldFrame()
  virtual void despawnEntity(stc::EntityId id, const std::string& name) = 0;              // by name unless empty
  virtual void clearWorld() = 0;
  virtual void resetWorld() = 0;  // the start scene again (~scene as the parameter server holds it now)
  // Writes the world as a scene file named `file` in ~save_dir; returns its
  // path. Throws InputError("file") for a bad name or a file that cannot be written.
  virtual std::string saveWorld(const std::string& file) = 0;
  virtual void setPaused(bool paused) = 0;
  virtual bool paused() const = 0;
  // Queues n ticks while paused; the tick number tick_stats reaches when they are done.
  virtual std::uint64_t queueSteps(std::uint32_t n) = 0;
  virtual std::uint64_t tickCount() const = 0;
  virtual const std::string& frameOf(stc::EntityId id) const = 0;  // tf frame of a live entity
  virtual void publishEntityList() = 0;  // ~entities now, if it changed
};

}  // namespace stc_ros
