#pragma once
// `ncfsim export OUTDIR --format abaqus|lsdyna`: the impregnated model of a transfer run (its
// results.h5, materials.csv, ties.csv) as an Abaqus input file or an LS-DYNA keyword deck, for
// users who run the crush in their own solver (transfer/deck_export.hpp).
#include <filesystem>
#include <string>

namespace ncfsim::workflow {

struct ExportResult {
  std::filesystem::path file;
  std::size_t nodes = 0, elements = 0, materials = 0, tie_pairs = 0;
  std::size_t bars = 0;  // kept stitches (not in elements)
};

/// Throws InputError (file = the folder) when the folder holds no completed transfer run or the
/// format is not abaqus / lsdyna.
ExportResult export_impregnated(const std::filesystem::path& dir, const std::string& format);

}  // namespace ncfsim::workflow
