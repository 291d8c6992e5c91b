#pragma once
// The transfer stage's case file (`[case] kind = "transfer"`, docs/case-file.md "Transfer"):
// which drape result to read, the fibre and resin datasheet values, the impregnation (Vf,
// compressive ratio), the trim and the resin bonds. Read by transfer, checked here, naming the
// case key on bad input.
#include <filesystem>
#include <string>
#include <vector>

#include "transfer/transfer_model.hpp"

namespace ncfsim::transfer {

struct TransferCase {
  std::filesystem::path file;
  std::string name, description;
  std::vector<std::string> overrides;
  std::filesystem::path results;   // the drape's results.h5 (absolute)
  long frame = -1;                 // frame index; -1: the last
  std::vector<std::string> parts;  // part names of the tows (empty: every tow hexahedron)
  TransferSpec spec;               // spec.parts filled by the stage from the result's part names
  bool frames_xdmf = true, figures = true;
};

/// Throws InputError naming the file and the key: a missing or unfinished drape result
/// (source.results: a summary.json beside it whose status is not "completed"), a fibre modulus of
/// zero, a Vf above 0.9069 (hexagonal packing), ...
TransferCase load_transfer_case(const std::filesystem::path& file,
                                const std::vector<std::string>& overrides);

}  // namespace ncfsim::transfer
