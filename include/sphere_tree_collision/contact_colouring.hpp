// Graph colouring of the solver's contacts, as Box2D v3 colours its
// constraints: the contacts of one colour share no movable body, so a colour's
// contacts can be solved at once, on any threads, in any order, with the same
// result; the colours are solved one after the other. Static bodies do not
// constrain colours (nothing writes their velocity).
//
// The unit is a group: the contacts of one body pair, solved one after the
// other by one thread. Groups come in the serial solver's order (up the
// contact graph from the ground). A group's colour is the lowest above every
// colour its movable bodies already have: each body meets its groups in the
// serial order, so a pass colour by colour updates every body in the same
// sequence, from the same values, as the serial pass did, and gives the same
// bits; the colours only say what may run at once.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace stc {

struct ColourGroup {
  static constexpr std::uint32_t kStatic = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t a = kStatic, b = kStatic;  // dense body indices; kStatic: a body that never moves
};

class ContactColouring {
 public:
  // Colours the groups, given in the serial order, of bodies in
  // [0, body_count); no allocation once warm.
  void assign(const std::vector<ColourGroup>& groups, std::size_t body_count);
  void reserve(std::size_t groups) { colour_.reserve(groups); }  // room for that many groups
  const std::vector<std::uint32_t>& colours() const { return colour_; }  // by group
  std::uint32_t colourCount() const { return colour_count_; }

 private:
  std::vector<std::uint32_t> next_;  // per body: the lowest colour its next group may take
  std::vector<std::uint32_t> colour_;
  std::uint32_t colour_count_ = 0;
};

}  // namespace stc
