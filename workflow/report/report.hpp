#pragma once
// report.html of a finished run: the case, the software version, the summary table, the energy
// balance, every figure (relative paths) and the case file. Plain HTML, no scripts.
#include <filesystem>

namespace ncfsim::workflow {

/// Writes out_dir/report.html (atomically) from summary.json, case.toml and figures/*.png.
void write_report(const std::filesystem::path& out_dir);

}  // namespace ncfsim::workflow
