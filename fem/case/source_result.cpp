#include "fem/case/source_result.hpp"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fem/case/stage_kinds.hpp"

namespace ncfsim::fem {

ResultRecord result_record(const std::filesystem::path& result_file) {
  ResultRecord r;
  const auto summary = result_file.parent_path() / "summary.json";
  std::ifstream in(summary);
  if (!in) return r;
  const auto j = nlohmann::json::parse(in, nullptr, false);
  r.found = true;
  if (!j.is_object()) return r;                       // stage and status stay empty: refused below
  r.stage = j.value(
      "stage", std::string(fem::stage_kind::kEngine));  // summaries before the key: engine runs
  r.status = j.value("status", std::string());
  return r;
}

void require_result_of(const TableReader& t, std::string_view key,
                       const std::filesystem::path& result_file,
                       std::initializer_list<std::string_view> stages, const std::string& needs) {
  const ResultRecord r = result_record(result_file);
  if (!r.found) return;
  const auto summary = (result_file.parent_path() / "summary.json").string();
  if (r.stage.empty())
    t.fail(key, summary + " beside " + result_file.string() + " cannot be read: " + needs);
  if (std::find(stages.begin(), stages.end(), r.stage) == stages.end())
    t.fail(key, result_file.string() + " is the result of a '" + r.stage + "' run (" + summary +
                    "): " + needs);
  if (r.status != "completed")
    t.fail(key, "the run in " + result_file.parent_path().string() + " did not complete (status '" +
                    r.status + "'): rerun or resume it first");
}

}  // namespace ncfsim::fem
