#pragma once
// Figures of a run: curve plots from history.csv and pictures of the last frame of results.h5,
// declared in figures.json (written at the start of a run from the case's [figures] section plus
// defaults per kind of case) and drawn off-screen. `ncfsim render OUTDIR` calls render_figures.
#include <filesystem>
#include <vector>

#include <spdlog/logger.h>

#include "workflow/case/engine_case.hpp"

namespace ncfsim::workflow {

/// figures.json: the case's plots and pictures plus the defaults (energy balance, tool force vs
/// displacement, probe displacements, deformed shape coloured by stress and displacement).
void write_figure_specs(const std::filesystem::path& out_dir, const EngineCase& ec);

/// Draws every figure of figures.json into out_dir/figures; returns the PNGs written. A figure
/// that cannot be drawn (missing column, no frame) is skipped with a warning.
std::vector<std::filesystem::path> render_figures(const std::filesystem::path& out_dir, spdlog::logger& log);

}  // namespace ncfsim::workflow
