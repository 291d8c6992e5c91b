#pragma once
// The block (structure-of-arrays state) behind an element group, for tests, benchmarks and the
// per-kind writers: block_of<Hex8Block>(group) is the group's block, or null for another kind.
// Each block header specialises it for its block.

namespace ncfsim::fem {

class ElementGroup;
template <class Block>
Block* block_of(ElementGroup& g);
template <class Block>
const Block* block_of(const ElementGroup& g);

/// The `block` of g when g is a `Group`, else null: what each kind's block_of specialisation is.
template <class Group>
auto* block_of_group(ElementGroup& g) {
  auto* h = dynamic_cast<Group*>(&g);
  return h ? &h->block : nullptr;
}
template <class Group>
const auto* block_of_group(const ElementGroup& g) {
  const auto* h = dynamic_cast<const Group*>(&g);
  return h ? &h->block : nullptr;
}

}  // namespace ncfsim::fem
