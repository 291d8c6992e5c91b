#pragma once
// `ncfsim export OUTDIR --format abaqus|lsdyna`: the impregnated model of a transfer run (its
// results.h5, materials.csv, ties.csv) as an Abaqus input file or an LS-DYNA keyword deck, for
// users who run the crush in their own solver (transfer/deck_export.hpp).
#include <filesystem>
#include <string>
#include <vector>

namespace ncfsim::workflow {

struct ExportResult {
  std::filesystem::path file;
  std::size_t nodes = 0, elements = 0, materials = 0, tie_pairs = 0;
  std::size_t bars = 0;  // kept stitches (not in elements)
};

/// Throws InputError (file = the folder) when the folder holds no completed transfer run or the
/// format is not abaqus / lsdyna.
ExportResult export_impregnated(const std::filesystem::path& dir, const std::string& format);

/// `ncfsim export CASE.toml --format ... [-o DIR] [--set ...]`: a crush case (kind = "crush") read
/// as `ncfsim run` reads it, written as a deck that runs the same crush (transfer/deck_export.hpp:
/// the tows' failure law, the resin bonds, the tools and the punch's motion, the controls) into
/// DIR/<case name>.k, .inp or _0000.rad + _0001.rad (OpenRadioss; DIR empty: results/<case
/// name>_<format>). Throws InputError for bad input or a case that is not a crush.
struct CrushExport {
  ExportResult result;
  std::vector<std::string> carried, left_out;  // transfer::deck_contents
};
CrushExport export_crush_case(const std::filesystem::path& case_file,
                              const std::vector<std::string>& overrides, const std::string& format,
                              const std::filesystem::path& out_dir);

}  // namespace ncfsim::workflow
