#pragma once
// What every element kernel reports per cycle: its energy increments and the stable step of its
// controlling element. Shared by all kinds (fem/elements/*_block.hpp).
#include <cstdint>

#include "fem/elements/element_kind.hpp"

namespace ncfsim::fem {

struct ElementEnergyIncrement {
  double internal = 0;       // stress power incl. physical stabilisation
  double stabilisation = 0;  // part of `internal` carried by the stabilisation
  double hourglass = 0;      // viscous (non-physical) hourglass work
  double kinetic = 0;        // change of the kinetic energy groups hold themselves (the
                             // rotations of shell nodes), part of the kinetic energy
};

struct StableStep {
  double dt = 1e300;
  std::int64_t element = -1;  // user id of the controlling element
  ElementKind kind = ElementKind::Hex8;
};

/// `b` replaces `a` when strictly smaller: the first controlling element in group order wins a tie.
inline void take_smaller(StableStep& a, const StableStep& b) {
  if (b.dt < a.dt) a = b;
}

}  // namespace ncfsim::fem
