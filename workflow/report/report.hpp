#pragma once
// report.html of a finished run: the case, the software version, the summary table, the energy
// balance, every figure (relative paths) and the case file. Plain HTML, no scripts.
#include <filesystem>
#include <string>

namespace ncfsim::workflow {

/// Writes out_dir/report.html (atomically) from summary.json, case.toml and figures/*.png.
void write_report(const std::filesystem::path& out_dir);

/// Text made safe inside HTML (& < > ").
std::string html_escape(const std::string& s);
/// The start of a report page up to <body>: title and the reports' one style sheet.
std::string html_head(const std::string& title);

}  // namespace ncfsim::workflow
