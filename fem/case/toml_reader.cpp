#include "fem/case/toml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    default: return "a date/time";
  }
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

// Strips array indices: "mesh.block[2].part" -> "mesh.block[].part".
std::string generic(const std::string& path) {
  std::string out;
  bool in_index = false;
  for (char c : path) {
    if (c == '[') in_index = true, out += "[]";
    else if (c == ']') in_index = false;
    else if (!in_index) out += c;
  }
  return out;
}

void collect_leaves(const toml::table& t, const std::string& prefix, std::vector<std::string>& out) {
  for (const auto& [k, v] : t) {
    const std::string path = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) {
      collect_leaves(*sub, path, out);
    } else if (const auto* arr = v.as_array(); arr && arr->is_array_of_tables()) {
      for (std::size_t i = 0; i < arr->size(); ++i)
        collect_leaves(*arr->get(i)->as_table(), path + "[" + std::to_string(i) + "]", out);
    } else {
      out.push_back(path);
    }
  }
}

toml::table* ensure_table(toml::table& root, const std::vector<std::string>& parts, std::size_t upto,
                          const std::string& file, const std::string& key) {
  toml::table* t = &root;
  for (std::size_t i = 0; i < upto; ++i) {
    // "block[2]": an entry of an array of tables.
    const auto open = parts[i].find('[');
    if (open != std::string::npos && parts[i].back() == ']') {
      const std::string name = parts[i].substr(0, open);
      std::size_t idx = 0;
      try {
        idx = std::stoul(parts[i].substr(open + 1, parts[i].size() - open - 2));
      } catch (const std::exception&) {
        throw InputError(file, key, "--set: bad index in '" + parts[i] + "'");
      }
      toml::node* an = t->get(name);
      toml::array* arr = an ? an->as_array() : nullptr;
      if (!arr || !arr->is_array_of_tables() || idx >= arr->size())
        throw InputError(file, key, "--set: there is no [[" + name + "]] entry " + std::to_string(idx));
      t = arr->get(idx)->as_table();
      continue;
    }
    toml::node* n = t->get(parts[i]);
    if (!n) {
      t->insert(parts[i], toml::table{});
      n = t->get(parts[i]);
    }
    if (!n->is_table())
      throw InputError(file, key, "--set cannot descend into '" + parts[i] + "', which is " + type_name(*n) +
                                      (n->is_array() ? " (use " + parts[i] + "[0]. for an entry of [[" + parts[i] + "]])" : ""));
    t = n->as_table();
  }
  return t;
}

}  // namespace

namespace {

toml::table parse_case_file(const std::filesystem::path& file) {
  const std::string fname = file.string();
  if (!std::filesystem::exists(file)) throw InputError(fname, "", "no such case file");
  if (std::filesystem::is_directory(file)) throw InputError(fname, "", "is a folder, not a case file");
  try {
    return toml::parse_file(fname);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << "TOML syntax error at line " << e.source().begin.line << ", column " << e.source().begin.column
       << ": " << e.description();
    throw InputError(fname, "", os.str());
  }
}

// Merges `inc` (from file `from`) into `into`: keys absent from `into` are added, tables merge
// key by key, arrays of tables are the included entries first, then the case's own; any other
// key given in both is an error (a case does not silently change what it includes).
void merge_included(toml::table& into, const toml::table& inc, const std::string& case_file,
                    const std::string& from, const std::string& path) {
  for (const auto& [k, v] : inc) {
    const std::string key = path.empty() ? std::string(k.str()) : path + "." + std::string(k.str());
    toml::node* mine = into.get(k.str());
    if (!mine) {
      into.insert(k.str(), v);
    } else if (mine->is_table() && v.is_table()) {
      merge_included(*mine->as_table(), *v.as_table(), case_file, from, key);
    } else if (mine->is_array_of_tables() && v.is_array_of_tables()) {
      toml::array merged = *v.as_array();
      for (const auto& e : *mine->as_array()) merged.push_back(e);
      into.insert_or_assign(k.str(), std::move(merged));
    } else {
      throw InputError(case_file, key,
                       "given both here and in the included file " + from +
                           " (change it there, or leave it out of one of them)");
    }
  }
}

// `include = ["tools.toml", ...]` at the top of a case: the keys of those files (paths relative
// to the case), merged into the case (merge_included). Shared descriptions (the tools of a
// forming process used by its meso and macro cases) live in one file.
toml::table resolve_includes(const std::filesystem::path& file, toml::table root, int depth) {
  const std::string fname = file.string();
  const toml::node* n = root.get("include");
  if (!n) return root;
  const toml::array* a = n->as_array();
  std::vector<std::string> files;
  if (const auto one = n->value<std::string>()) files.push_back(*one);
  else if (a)
    for (const auto& e : *a) {
      const auto f = e.value<std::string>();
      if (!f || f->empty()) throw InputError(fname, "include", "must be an array of file paths");
      files.push_back(*f);
    }
  else
    throw InputError(fname, "include", "must be a file path or an array of file paths");
  if (depth >= 4) throw InputError(fname, "include", "includes nest more than 4 deep (a cycle?)");
  root.erase("include");
  for (const auto& f : files) {
    std::filesystem::path inc = f;
    if (inc.is_relative()) inc = file.parent_path() / inc;
    if (!std::filesystem::is_regular_file(inc))
      throw InputError(fname, "include", "no such file: " + inc.string());
    toml::table t = resolve_includes(inc, parse_case_file(inc), depth + 1);
    if (t.contains("case"))
      throw InputError(inc.string(), "case",
                       "an included file holds shared sections only, not [case] (included by " +
                           fname + ")");
    merge_included(root, t, fname, inc.string(), "");
  }
  return root;
}

// `--set` and a variant's `set`: "a.b[2].c=value", the value in TOML syntax or a bare word (a
// string); tables on the way are made as needed.
void apply_overrides(toml::table& root, const std::vector<std::string>& overrides,
                     const std::string& fname) {
  for (const std::string& ov : overrides) {
    const auto eq = ov.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(fname, ov, "--set needs KEY=VALUE (e.g. --set mesh.resolution=coarse)");
    auto trim = [](std::string s) {
      const auto a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
      return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    const std::string key = trim(ov.substr(0, eq)), value = trim(ov.substr(eq + 1));
    std::vector<std::string> parts;
    std::stringstream ss(key);
    for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
    if (parts.empty() || std::any_of(parts.begin(), parts.end(), [](auto& p) { return p.empty(); }))
      throw InputError(fname, key, "--set: malformed key");
    toml::table* t = ensure_table(root, parts, parts.size() - 1, fname, key);
    toml::table parsed;
    try {
      parsed = toml::parse("v = " + value);
    } catch (const toml::parse_error&) {
      parsed = toml::table{{"v", value}};  // a bare word is a string
    }
    t->insert_or_assign(parts.back(), *parsed.get("v"));
  }
}

// A variant of another case ([case] base = "other.toml", set = ["key=value", ...]): the base
// case, with the sections of the variant's own `include` files added (another fabric to drape),
// then the variant's changes, named and described by the variant. It holds only [case] (and
// `include`), so that each of its changes is one visible line and the base stays the one
// description of the rest.
toml::table resolve_base(const std::filesystem::path& file, toml::table root, int depth) {
  const std::string fname = file.string();
  const toml::table* c = root["case"].as_table();
  if (!c || !c->contains("base")) return resolve_includes(file, std::move(root), 0);
  const auto base = (*c)["base"].value<std::string>();
  if (!base || base->empty()) throw InputError(fname, "case.base", "must be the path of a case file");
  if (depth >= 4) throw InputError(fname, "case.base", "bases nest more than 4 deep (a cycle?)");
  for (const auto& [k, v] : root)
    if (k.str() != "case" && k.str() != "include")
      throw InputError(fname, std::string(k.str()),
                       "a case with case.base holds only [case] (and include): give its changes in "
                       "case.set (e.g. set = [\"mesh.fabric[0].stitch = 'none'\"])");
  std::vector<std::string> sets;
  if (c->contains("set")) {
    const toml::array* a = (*c)["set"].as_array();
    if (!a) throw InputError(fname, "case.set", "must be an array of \"key=value\" strings");
    for (const auto& e : *a) {
      const auto s = e.value<std::string>();
      if (!s) throw InputError(fname, "case.set", "must be an array of \"key=value\" strings");
      sets.push_back(*s);
    }
  }
  std::filesystem::path base_file = *base;
  if (base_file.is_relative()) base_file = file.parent_path() / base_file;
  if (!std::filesystem::is_regular_file(base_file))
    throw InputError(fname, "case.base", "no such case file: " + base_file.string());
  CaseDocument b = CaseDocument::load_resolved(base_file, {}, depth + 1);
  toml::table out = b.root();
  // The variant's includes, merged as the base's own are: a key the base gives too is bad input.
  if (const toml::node* include = root.get("include")) {
    toml::table inc;
    inc.insert("include", *include);
    inc = resolve_includes(file, std::move(inc), 0);  // checks the list's form and files
    std::string names;
    if (const auto one = include->value<std::string>()) names = *one;
    if (const toml::array* a = include->as_array())
      for (const auto& e : *a) names += (names.empty() ? "" : ", ") + e.value_or(std::string());
    merge_included(out, inc, base_file.string(), names + " (included by " + fname + ")", "");
  }
  apply_overrides(out, sets, fname);
  toml::table* oc = out["case"].as_table();
  if (!oc) {
    out.insert("case", toml::table{});
    oc = out["case"].as_table();
  }
  for (const auto& [k, v] : *c)
    if (k.str() != "base" && k.str() != "set") oc->insert_or_assign(k.str(), v);
  return out;
}

}  // namespace

CaseDocument CaseDocument::load(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  return load_resolved(file, overrides, 0);
}

CaseDocument CaseDocument::load_resolved(const std::filesystem::path& file,
                                         const std::vector<std::string>& overrides, int depth) {
  CaseDocument doc;
  doc.file_ = file;
  const std::string fname = file.string();
  doc.root_ = resolve_base(file, parse_case_file(file), depth);
  apply_overrides(doc.root_, overrides, fname);
  return doc;
}

void CaseDocument::apply_laws_files() {
  toml::table* c = root_["case"].as_table();
  if (!c || !c->contains("laws")) return;
  mark_read("case.laws");
  std::vector<std::string> files;
  const toml::node& n = *c->get("laws");
  if (const auto one = n.value<std::string>()) {
    files.push_back(*one);
  } else if (const toml::array* a = n.as_array()) {
    for (const auto& e : *a) {
      const auto f = e.value<std::string>();
      if (!f)
        throw InputError(file_.string(), "case.laws", "must be a file path or a list of them");
      files.push_back(*f);
    }
  } else {
    throw InputError(file_.string(), "case.laws", "must be a file path or a list of them");
  }
  static constexpr const char* kLawArrays[] = {"material", "bar_law", "membrane_law"};
  for (const auto& name : files) {
    std::filesystem::path f = name;
    if (f.is_relative()) f = file_.parent_path() / f;
    if (!std::filesystem::is_regular_file(f))
      throw InputError(file_.string(), "case.laws", "no such file: " + f.string());
    const toml::table laws = parse_case_file(f);
    for (const auto& [key, v] : laws) {
      const std::string k(key.str());
      const bool law = std::any_of(std::begin(kLawArrays), std::end(kLawArrays),
                                   [&](const char* a) { return k == a; });
      const toml::array* given = v.as_array();
      if (!law || !given || !given->is_array_of_tables())
        throw InputError(f.string(), k,
                         "a laws file holds [[material]], [[bar_law]] and [[membrane_law]] "
                         "tables only (read by case.laws of " +
                             file_.string() + ")");
      toml::array* mine = root_[k].as_array();
      for (std::size_t i = 0; i < given->size(); ++i) {
        const toml::table& t = *given->get(i)->as_table();
        const std::string at = k + "[" + std::to_string(i) + "].name";
        const auto law_name = t["name"].value<std::string>();
        if (!law_name)
          throw InputError(f.string(), at, "missing (the name of the law it replaces)");
        std::string names;
        bool replaced = false;
        for (std::size_t j = 0; mine && j < mine->size(); ++j) {
          toml::table* m = mine->get(j)->as_table();
          const auto mn = m ? (*m)["name"].value<std::string>() : std::nullopt;
          if (!mn) continue;
          if (*mn == *law_name) {
            *m = t;
            replaced = true;
            laws_replaced_.push_back("[[" + k + "]] '" + *law_name + "' from " + f.string());
            break;
          }
          names += (names.empty() ? "" : ", ") + *mn;
        }
        if (!replaced)
          throw InputError(f.string(), at,
                           "the case " + file_.string() + " has no [[" + k + "]] named '" +
                               *law_name +
                               "' to replace (it has: " + (names.empty() ? "none" : names) + ")");
      }
    }
  }
}

void CaseDocument::check_unknown_keys() const {
  std::vector<std::string> leaves;
  collect_leaves(root_, "", leaves);
  std::set<std::string> known_generic;
  for (const auto& r : read_) known_generic.insert(generic(r));
  for (const auto& leaf : leaves) {
    if (read_.count(leaf)) continue;
    std::string hint;
    std::size_t best = 4;
    const std::string g = generic(leaf);
    for (const auto& k : known_generic) {
      const std::size_t d = edit_distance(g, k);
      if (d < best) best = d, hint = k;
    }
    if (!hint.empty()) {  // show the hint with this key's own table path
      const auto dot_leaf = leaf.rfind('.'), dot_hint = hint.rfind('.');
      const std::string tail = dot_hint == std::string::npos ? hint : hint.substr(dot_hint + 1);
      hint = dot_leaf == std::string::npos ? tail : leaf.substr(0, dot_leaf + 1) + tail;
    }
    throw InputError(file_.string(), leaf,
                     "unknown key" + (hint.empty() ? std::string(" (see docs/case-file.md)")
                                                   : " (did you mean '" + hint + "'?)"));
  }
}

TableReader::TableReader(CaseDocument& doc, const toml::table& table, std::string path)
    : doc_(&doc), table_(table), path_(std::move(path)) {}

std::string TableReader::key_path(std::string_view key) const {
  if (!table_.contains(key) && defaults_ && defaults_->has(key)) return defaults_->key_path(key);
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

TableReader TableReader::with_defaults(const TableReader& defaults) const {
  TableReader r = *this;
  r.defaults_ = std::make_shared<const TableReader>(defaults);
  return r;
}

void TableReader::fail(std::string_view key, const std::string& message) const {
  throw InputError(doc_->file().string(), key_path(key), message);
}

const toml::node& TableReader::require(std::string_view key) const {
  const toml::node* n = table_.get(key);
  if (!n && defaults_ && defaults_->has(key)) return defaults_->require(key);
  if (!n) fail(key, "missing (required)");
  doc_->mark_read(key_path(key));
  return *n;
}

double TableReader::as_number(std::string_view key, const toml::node& n) const {
  if (auto v = n.value_exact<double>()) return *v;
  if (auto v = n.value_exact<std::int64_t>()) return static_cast<double>(*v);
  // "&fabric.saertex_pm45.friction_tow_tow": the number another key of the case gives (as
  // LS-DYNA's &parameter), so that a datum shared by many tables is written once.
  if (const auto ref = n.value_exact<std::string>(); ref && ref->size() > 1 && (*ref)[0] == '&') {
    const std::string path = ref->substr(1);
    const toml::node* r = doc_->root().at_path(path).node();
    if (!r)
      fail(key, "refers to '" + path + "', which the case and the files it includes do not give");
    doc_->mark_read(path);
    if (auto v = r->value_exact<double>()) return *v;
    if (auto v = r->value_exact<std::int64_t>()) return static_cast<double>(*v);
    fail(key, "refers to '" + path + "', which is " + type_name(*r) + ", not a number");
  }
  fail(key, "must be a number, got " + type_name(n));
}

double TableReader::number(std::string_view key, Range range) const {
  const double v = as_number(key, require(key));
  if (!range.contains(v)) throw InputError::out_of_range(file().string(), key_path(key), v, range);
  return v;
}

double TableReader::number(std::string_view key, double fallback, Range range) const {
  return has(key) ? number(key, range) : fallback;
}

std::int64_t TableReader::integer(std::string_view key, std::int64_t lo, std::int64_t hi) const {
  const toml::node& n = require(key);
  const auto v = n.value_exact<std::int64_t>();
  if (!v) fail(key, "must be an integer, got " + type_name(n));
  if (*v < lo || *v > hi) {
    const std::string allowed = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    throw InputError(file().string(), key_path(key),
                     "value " + std::to_string(*v) + " out of range, allowed " + allowed,
                     std::to_string(*v), allowed);
  }
  return *v;
}

std::int64_t TableReader::integer(std::string_view key, std::int64_t fallback, std::int64_t lo,
                                  std::int64_t hi) const {
  return has(key) ? integer(key, lo, hi) : fallback;
}

bool TableReader::boolean(std::string_view key, bool fallback) const {
  if (!has(key)) return fallback;
  const toml::node& n = require(key);
  const auto v = n.value_exact<bool>();
  if (!v) fail(key, "must be true or false, got " + type_name(n));
  return *v;
}

std::string TableReader::string(std::string_view key) const {
  const toml::node& n = require(key);
  const auto v = n.value_exact<std::string>();
  if (!v) fail(key, "must be a string, got " + type_name(n));
  return *v;
}

std::string TableReader::string(std::string_view key, const std::string& fallback) const {
  return has(key) ? string(key) : fallback;
}

std::string TableReader::choice(std::string_view key, const std::vector<std::string>& choices,
                                const std::string& fallback) const {
  const std::string v = string(key, fallback);
  if (std::find(choices.begin(), choices.end(), v) == choices.end())
    throw InputError::not_one_of(file().string(), key_path(key), v, choices);
  return v;
}

std::vector<double> TableReader::numbers(std::string_view key, Range range, std::size_t min_size) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  if (!a) fail(key, "must be an array of numbers, got " + type_name(n));
  if (a->size() < min_size) fail(key, "needs at least " + std::to_string(min_size) + " values");
  std::vector<double> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const double v = as_number(key, *a->get(i));
    if (!range.contains(v))
      throw InputError::out_of_range(file().string(), key_path(key), v, range, static_cast<long>(i));
    out.push_back(v);
  }
  return out;
}

std::array<double, 3> TableReader::vec3(std::string_view key, Range r) const {
  const auto v = numbers(key, r, 3);
  if (v.size() != 3) fail(key, "must hold exactly 3 numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

std::array<double, 3> TableReader::vec3_or(std::string_view key, std::array<double, 3> fallback, Range r) const {
  return has(key) ? vec3(key, r) : fallback;
}

std::vector<std::string> TableReader::strings(std::string_view key) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  if (!a) fail(key, "must be an array of strings, got " + type_name(n));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const auto v = a->get(i)->value_exact<std::string>();
    if (!v) fail(key, "entry " + std::to_string(i) + " must be a string");
    out.push_back(*v);
  }
  return out;
}

std::optional<TableReader> TableReader::table(std::string_view key) const {
  const toml::node* n = table_.get(key);
  if (!n) return std::nullopt;
  if (!n->is_table()) fail(key, "must be a table, got " + type_name(*n));
  return TableReader(*doc_, *n->as_table(), key_path(key));
}

TableReader TableReader::required_table(std::string_view key) const {
  auto t = table(key);
  if (!t) fail(key, "missing (required section [" + key_path(key) + "])");
  return *t;
}

std::vector<TableReader> TableReader::tables(std::string_view key) const {
  std::vector<TableReader> out;
  const toml::node* n = table_.get(key);
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a || !a->is_array_of_tables())
    fail(key, "must be an array of tables ([[" + key_path(key) + "]]), got " + type_name(*n));
  for (std::size_t i = 0; i < a->size(); ++i)
    out.emplace_back(*doc_, *a->get(i)->as_table(), key_path(key) + "[" + std::to_string(i) + "]");
  return out;
}

std::vector<std::string> TableReader::keys() const {
  std::vector<std::string> out;
  for (const auto& [k, v] : table_) out.emplace_back(k.str());
  return out;
}

}  // namespace ncfsim::fem
