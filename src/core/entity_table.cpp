// EntityTable: the entities' dense rows and their id and name maps.
#include "entity_table.hpp"

#include "flat_hash_map.hpp"
#include "grow_capacity.hpp"

#include <cassert>
#include <utility>

namespace stc {

EntityTable::EntityTable() : index_of_(std::make_unique<detail::FlatHashMap>()) {}
EntityTable::~EntityTable() = default;
EntityTable::EntityTable(EntityTable&&) noexcept = default;
EntityTable& EntityTable::operator=(EntityTable&&) noexcept = default;

std::optional<std::size_t> EntityTable::indexOf(EntityId id) const {
  const std::uint32_t found = index_of_->find(id);
  if (found == detail::FlatHashMap::kMissing) return std::nullopt;
  return static_cast<std::size_t>(found);
}

std::optional<EntityId> EntityTable::findByName(const std::string& name) const {
  const auto it = id_by_name_.find(name);
  if (it == id_by_name_.end()) return std::nullopt;
  return it->second;
}

EntityId EntityTable::addRow(const BodyState& body, ShapeId shape, BoxMode box_mode, double density, std::string name,
                             EntityId id) {
  assert((id != kInvalidEntity ? !indexOf(id) : idsLeft()) && (name.empty() || id_by_name_.count(name) == 0));
  if (id == kInvalidEntity) {
    id = next_id_++;
  } else if (id >= next_id_ && next_id_ != kInvalidEntity) {
    next_id_ = id + 1;  // kInvalidEntity after the last id: none left
  }
  const std::size_t index = ids_.size();
  ids_.push_back(id);
  bodies_.push_back(body);
  body_shapes_.push_back(shape);
  box_modes_.push_back(box_mode);
  densities_.push_back(density);
  if (!name.empty()) id_by_name_.emplace(name, id);
  names_.push_back(std::move(name));
  index_of_->set(id, static_cast<std::uint32_t>(index));
  return id;
}

void EntityTable::removeRow(std::size_t index) {
  assert(index < ids_.size());
  const std::size_t last = ids_.size() - 1;
  if (!names_[index].empty()) id_by_name_.erase(names_[index]);
  index_of_->erase(ids_[index]);
  if (index != last) {
    ids_[index] = ids_[last];
    bodies_[index] = bodies_[last];
    body_shapes_[index] = body_shapes_[last];
    box_modes_[index] = box_modes_[last];
    densities_[index] = densities_[last];
    names_[index] = std::move(names_[last]);
    index_of_->set(ids_[index], static_cast<std::uint32_t>(index));
  }
  ids_.pop_back();
  bodies_.pop_back();
  body_shapes_.pop_back();
  box_modes_.pop_back();
  densities_.pop_back();
  names_.pop_back();
}

void EntityTable::clearRows() {
  ids_.clear();
  bodies_.clear();
  body_shapes_.clear();
  box_modes_.clear();
  densities_.clear();
  names_.clear();
  *index_of_ = detail::FlatHashMap();
  id_by_name_.clear();
}

void EntityTable::releaseRowMemory() {
  dropSpareCapacity(ids_);
  dropSpareCapacity(bodies_);
  dropSpareCapacity(body_shapes_);
  dropSpareCapacity(box_modes_);
  dropSpareCapacity(densities_);
  dropSpareCapacity(names_);
  index_of_->shrinkToFit();
  id_by_name_.rehash(0);  // as few buckets as its entries need
}

}  // namespace stc
