#include "workflow/stages/workflow_case.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>

#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"

namespace ncfsim::workflow {

namespace {

std::string first_key(const std::string& item) {
  const auto eq = item.find('=');
  const std::string key = item.substr(0, eq);
  const auto dot = key.find_first_of(".[");
  return key.substr(0, dot);
}

// Every stage after its upstream stages, in file order where the inputs leave a choice (Kahn's
// algorithm); a cycle is bad input naming the stages on it.
std::vector<WorkflowStageSpec> run_order(std::vector<WorkflowStageSpec> stages,
                                         const std::string& file) {
  std::vector<WorkflowStageSpec> order;
  std::vector<char> done(stages.size(), 0);
  std::set<std::string> finished;
  while (order.size() < stages.size()) {
    bool progressed = false;
    for (std::size_t k = 0; k < stages.size(); ++k) {
      if (done[k]) continue;
      const auto& up = stages[k].after;
      if (std::all_of(up.begin(), up.end(), [&](const auto& u) { return finished.count(u) > 0; })) {
        done[k] = 1;
        finished.insert(stages[k].name);
        order.push_back(stages[k]);
        progressed = true;
        break;  // back to the first stage: file order among the ready ones
      }
    }
    if (!progressed) {
      std::string cycle;
      for (std::size_t k = 0; k < stages.size(); ++k)
        if (!done[k]) cycle += (cycle.empty() ? "" : ", ") + stages[k].name;
      throw InputError(
          file, "stage",
          "the stages " + cycle + " wait for each other (a cycle through their inputs / after)");
    }
  }
  return order;
}

}  // namespace

WorkflowCase load_workflow_case(const std::filesystem::path& file,
                                const std::vector<std::string>& overrides) {
  fem::CaseDocument doc = fem::CaseDocument::load(file, {});
  const fem::TableReader root(doc, doc.root(), "");
  const std::string fname = file.string();
  WorkflowCase wc;
  wc.file = file;
  const auto c = root.required_table("case");
  wc.name = c.string("name");
  wc.description = c.string("description", "");
  c.mark("kind");
  const auto dir = file.parent_path();
  std::set<std::string> names;
  const auto tables = root.tables("stage");
  if (tables.empty()) root.fail("stage", "missing: a workflow needs at least one [[stage]]");
  for (const auto& t : tables) {
    WorkflowStageSpec s;
    s.name = t.string("name");
    if (s.name.empty() || s.name.find_first_of(" ./\\=[]") != std::string::npos)
      t.fail("name", "'" + s.name + "' must be a plain word (it names the stage's folder)");
    if (!names.insert(s.name).second) t.fail("name", "two stages are named '" + s.name + "'");
    const std::string rel = t.string("case");
    s.case_file = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : dir / rel;
    if (!std::filesystem::is_regular_file(s.case_file))
      t.fail("case", "the stage case " + s.case_file.string() + " does not exist");
    if (const auto in = t.table("inputs")) {
      // The key must be one the stage's case has: a key it does not have would take the path
      // nowhere, and the stage would read whatever its case names instead.
      const fem::CaseDocument sd = fem::CaseDocument::load(s.case_file, {});
      for (const auto& key : in->keys()) {
        if (!sd.root().at_path(key))
          in->fail(key, "is not a key of stage '" + s.name + "''s case " + s.case_file.string() +
                            " (an input hands the upstream results to a key the case has, e.g. "
                            "\"source.results\" of a transfer or \"model.source\" of a crush)");
        s.inputs.emplace_back(key, in->string(key));
      }
    }
    // The stage's own changes to its case (a virtual test on the CI mesh), as --set items
    // routed to it, before the command line's.
    if (t.has("set")) s.overrides = t.strings("set");
    for (const auto& [key, up] : s.inputs) s.after.push_back(up);
    if (t.has("after"))
      for (const auto& up : t.strings("after")) s.after.push_back(up);
    s.ranks = static_cast<int>(t.integer("ranks", 0, 1, 4096));
    std::sort(s.after.begin(), s.after.end());
    s.after.erase(std::unique(s.after.begin(), s.after.end()), s.after.end());
    wc.stages.push_back(std::move(s));
  }
  for (std::size_t k = 0; k < wc.stages.size(); ++k)
    for (const auto& up : wc.stages[k].after) {
      if (up == wc.stages[k].name)
        tables[k].fail("inputs", "stage '" + up + "' cannot take its own results");
      if (!names.count(up))
        tables[k].fail(wc.stages[k].inputs.empty() ? "after" : "inputs",
                       "names no stage: '" + up +
                           "' (stages: " + fmt::format("{}", fmt::join(names, ", ")) + ")");
    }
  doc.check_unknown_keys();
  wc.stages = run_order(std::move(wc.stages), fname);

  // Overrides: to the stage named by the first key, or to every stage whose case has that table.
  for (const auto& item : overrides) {
    if (item.find('=') == std::string::npos)
      throw InputError(fname, item,
                       "--set needs KEY=VALUE (e.g. --set drape.mesh.resolution=coarse)");
    const std::string head = first_key(item);
    auto named = std::find_if(wc.stages.begin(), wc.stages.end(),
                              [&](const auto& s) { return s.name == head; });
    if (named != wc.stages.end()) {
      const std::string rest = item.substr(head.size() + 1);
      if (rest.empty() || rest.front() == '=')
        throw InputError(fname, item, "names the stage '" + head + "' but no key of it");
      named->overrides.push_back(rest);
      continue;
    }
    bool taken = false;
    for (auto& s : wc.stages) {
      const fem::CaseDocument sd = fem::CaseDocument::load(s.case_file, {});
      if (sd.root().contains(head)) {
        s.overrides.push_back(item);
        taken = true;
      }
    }
    if (!taken) {
      std::string list;
      for (const auto& s : wc.stages) list += (list.empty() ? "" : ", ") + s.name;
      throw InputError(fname, item,
                       "neither names a stage nor a table any stage's case has (stages: " + list +
                           "; e.g. --set " + wc.stages.front().name + "." + item + ")");
    }
  }
  return wc;
}

}  // namespace ncfsim::workflow
