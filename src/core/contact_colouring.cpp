// Graph colouring of the solver's contact groups (contact_colouring.hpp).
#include "sphere_tree_collision/contact_colouring.hpp"

#include <algorithm>

namespace stc {

void ContactColouring::assign(const std::vector<ColourGroup>& groups, std::size_t body_count) {
  next_.assign(body_count, 0);
  colour_.resize(groups.size());
  colour_count_ = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ColourGroup& group = groups[g];
    const std::uint32_t a = group.a != ColourGroup::kStatic ? next_[group.a] : 0;
    const std::uint32_t b = group.b != ColourGroup::kStatic ? next_[group.b] : 0;
    const std::uint32_t colour = std::max(a, b);
    if (group.a != ColourGroup::kStatic) next_[group.a] = colour + 1;
    if (group.b != ColourGroup::kStatic) next_[group.b] = colour + 1;
    colour_[g] = colour;
    colour_count_ = std::max(colour_count_, colour + 1);
  }
}

}  // namespace stc
