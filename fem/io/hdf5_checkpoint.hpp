#pragma once
// The checkpoint file (<out>/checkpoint.h5, docs/output.md): a CheckpointTree (fem/checkpoint.hpp)
// as HDF5, groups as groups, scalars as attributes, arrays as 1-D datasets.
#include <filesystem>

#include "fem/checkpoint.hpp"

namespace ncfsim::fem::io {

/// Writes the tree to `path` atomically: `path`.tmp is written, closed and fsynced, then renamed
/// over `path`; a write that fails or is killed leaves the previous file as it was. Throws
/// std::runtime_error naming the file and object.
void write_checkpoint_file(const std::filesystem::path& path, const CheckpointTree& tree);

/// Reads a checkpoint file written by write_checkpoint_file. Throws CheckpointMismatch naming the
/// file when it cannot be opened or read as one.
CheckpointTree read_checkpoint_file(const std::filesystem::path& path);

}  // namespace ncfsim::fem::io
