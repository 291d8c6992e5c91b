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

}  // namespace ncfsim::fem
