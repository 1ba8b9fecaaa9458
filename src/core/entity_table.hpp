// EntityTable: the entities' rows. Each per-entity fact is one flat array
// indexed by a dense index 0..entityCount(), with ids and names mapped to
// it; removing a row moves the last row into its place (swap-remove), so the
// arrays stay dense. Ids are never reused.
//
// What else is kept per entity follows each add and remove in one place,
// World::addEntity / World::removeEntity: Islands, IslandLevels and
// StaticCover (by dense index, with the same swap-remove) and the broad
// phase (by id). World::Parts holds the table (world_parts.hpp); the tick
// reads the arrays through the inline calls below.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/types.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace stc {

namespace detail {
class FlatHashMap;  // src/core/flat_hash_map.hpp
}  // namespace detail

class EntityTable {
 public:
  EntityTable();
  ~EntityTable();
  EntityTable(EntityTable&&) noexcept;
  EntityTable& operator=(EntityTable&&) noexcept;

  std::size_t entityCount() const { return ids_.size(); }
  const std::vector<EntityId>& entityIds() const { return ids_; }
  const std::vector<BodyState>& bodies() const { return bodies_; }
  std::vector<BodyState>& bodies() { return bodies_; }
  const std::vector<ShapeId>& bodyShapes() const { return body_shapes_; }
  const std::vector<std::string>& bodyNames() const { return names_; }
  // The density each entity was added with (kg/m^3; a static body's too),
  // and its box mode as resolved (never Auto): what a saved world needs
  // that BodyState does not keep.
  const std::vector<double>& bodyDensities() const { return densities_; }
  const std::vector<BoxMode>& bodyBoxModes() const { return box_modes_; }
  std::optional<std::size_t> indexOf(EntityId id) const;
  std::optional<EntityId> findByName(const std::string& name) const;
  // Whether one more entity can get an id (they are never reused).
  bool idsLeft() const { return next_id_ != kInvalidEntity; }
  // Entity id -> dense index, open addressing on flat arrays
  // (flat_hash_map.hpp: find gives kMissing for an unknown id): the pair
  // walk of every tick looks up two per broad-phase pair (a settled pile of
  // 5,000 rocks: ~50,000 pairs; docs/sleeping.md).
  const detail::FlatHashMap& indexMap() const { return *index_of_; }

  // A row at the end (dense index entityCount() - 1) with the next id, or
  // `id` (unused; later ids count on from it), which is returned. The name
  // is empty or unused (checked by the caller).
  EntityId addRow(const BodyState& body, ShapeId shape, BoxMode box_mode, double density, std::string name,
                  EntityId id = kInvalidEntity);
  // Row `index` removed: the last row takes its place.
  void removeRow(std::size_t index);
  // Every row removed; ids go on counting.
  void clearRows();
  // The arrays and maps cut to what the rows hold (after a flood of removals).
  void releaseRowMemory();

 private:
  // By dense index; ids_ maps dense -> id.
  std::vector<EntityId> ids_;
  std::vector<BodyState> bodies_;
  std::vector<ShapeId> body_shapes_;
  std::vector<BoxMode> box_modes_;
  std::vector<double> densities_;
  std::vector<std::string> names_;
  std::unique_ptr<detail::FlatHashMap> index_of_;  // indexMap()
  std::unordered_map<std::string, EntityId> id_by_name_;
  EntityId next_id_ = 0;
};

}  // namespace stc
