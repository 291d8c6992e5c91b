#include "workflow/report/report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

namespace {

std::string escape(const std::string& s) { return html_escape(s); }

void flatten(const nlohmann::json& j, const std::string& prefix,
             std::vector<std::pair<std::string, std::string>>& rows) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it)
      flatten(it.value(), prefix.empty() ? it.key() : prefix + "." + it.key(), rows);
  } else if (j.is_string()) {
    rows.emplace_back(prefix, j.get<std::string>());
  } else {
    rows.emplace_back(prefix, j.dump());
  }
}

// A number of the summary, NaN where it is missing or null (a run stopped by a non-finite state
// writes its energies as null).
double summary_number(const nlohmann::json& s, const char* key, double missing) {
  const auto it = s.find(key);
  if (it == s.end()) return missing;
  return it->is_number() ? it->get<double>() : std::nan("");
}

}  // namespace

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

std::string html_head(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" +
         html_escape(title) +
         "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
         "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 8px;"
         "text-align:left;font-size:90%}img{max-width:100%;border:1px solid #ddd;margin:6px 0}"
         "pre{background:#f6f6f6;padding:8px;overflow-x:auto}.bad{color:#b00;font-weight:bold}"
         ".ok{color:#070;font-weight:bold}</style></head><body>\n";
}

void write_report(const std::filesystem::path& dir) {
  std::ifstream in(dir / "summary.json");
  if (!in)
    throw std::runtime_error((dir / "summary.json").string() +
                             " not found (is this a run's output folder?)");
  const nlohmann::json s = nlohmann::json::parse(in);
  const std::string name = s.value("case", "ncfsim run");
  std::ostringstream h;
  h << html_head(name + " - ncfsim report");
  h << "<h1>" << escape(name) << "</h1>\n";
  const std::string status = s.value("status", "unknown");
  const double err = summary_number(s, "energy_balance_error", 0.0);
  const double lim = summary_number(s, "energy_balance_limit", 0.05);
  h << "<p>ncfsim " << escape(s.value("ncfsim_version", "?")) << " &middot; stage "
    << escape(s.value("stage", "?")) << " &middot; status <span class=\""
    << (status == "completed" ? "ok" : "bad") << "\">" << escape(status) << "</span>";
  if (s.contains("energy_balance_error"))  // explicit runs; a transfer has no time loop
    h << " &middot; energy balance error <span class=\"" << (err <= lim ? "ok" : "bad") << "\">"
      << (std::isfinite(err) ? escape(nlohmann::json(100 * err).dump()) + " %"
                             : std::string("not finite"))
      << "</span> (limit " << 100 * lim << " %)";
  h << "</p>\n";
  if (s.contains("error"))
    h << "<p class=\"bad\">" << escape(s["error"].get<std::string>()) << "</p>\n";

  std::vector<std::filesystem::path> figs;
  if (std::filesystem::exists(dir / "figures"))
    for (const auto& e : std::filesystem::directory_iterator(dir / "figures"))
      if (e.path().extension() == ".png") figs.push_back(e.path().filename());
  std::sort(figs.begin(), figs.end(), [](const auto& a, const auto& b) {
    const bool ea = a.string().rfind("energy_balance", 0) == 0,
               eb = b.string().rfind("energy_balance", 0) == 0;
    return ea != eb ? ea : a < b;
  });
  h << "<h2>Figures</h2>\n";
  if (figs.empty()) h << "<p>No figures (run <code>ncfsim render</code> on this folder).</p>\n";
  for (const auto& f : figs)
    h << "<figure><img src=\"figures/" << escape(f.string()) << "\" alt=\""
      << escape(f.stem().string()) << "\"><figcaption>" << escape(f.stem().string())
      << "</figcaption></figure>\n";

  h << "<h2>Summary</h2>\n<table><tr><th>key</th><th>value</th></tr>\n";
  std::vector<std::pair<std::string, std::string>> rows;
  flatten(s, "", rows);
  for (const auto& [k, v] : rows)
    h << "<tr><td>" << escape(k) << "</td><td>" << escape(v) << "</td></tr>\n";
  h << "</table>\n";
  if (std::filesystem::exists(dir / "case.toml"))
    h << "<h2>Case file</h2>\n<pre>" << escape(read_file(dir / "case.toml")) << "</pre>\n";
  h << "<p>Results: <a href=\"results.xdmf\">results.xdmf</a> (ParaView), <a "
       "href=\"history.csv\">history.csv</a>, "
       "<a href=\"summary.json\">summary.json</a>, <a "
       "href=\"log.txt\">log.txt</a></p>\n</body></html>\n";
  write_file_atomically(dir / "report.html", h.str());
}

}  // namespace ncfsim::workflow
