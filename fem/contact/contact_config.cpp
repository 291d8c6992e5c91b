#include "fem/contact/contact_config.hpp"

#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {

// The key of a field: "<key_path>.<field>" for a contact read from a case file, else
// "contact.<name>.<field>".
std::string key_of(const std::string& key_path, const std::string& name, const std::string& field) {
  return (key_path.empty() ? "contact." + name : key_path) + "." + field;
}

}  // namespace

void validate(const PenaltyContactConfig& c) {
  const std::string& f = c.source_file;
  const bool from_case = !c.key_path.empty();
  auto key = [&](const std::string& field) { return key_of(c.key_path, c.name, field); };
  // A case file names the entries [[contact.group]] and [[contact.pair]]; code, groups and pairs.
  const std::string groups_key = key(from_case ? "group" : "groups");
  auto pair_key = [&](std::size_t p) {
    return from_case ? key("pair[" + std::to_string(p) + "]") : key("pairs");
  };
  if (c.name.empty())
    throw InputError(f, from_case ? key("name") : "contact.name", "a contact needs a name");
  if (c.groups.empty())
    throw InputError(f, groups_key, "a penalty contact needs at least one [[contact.group]]");
  for (std::size_t g = 0; g < c.groups.size(); ++g) {
    if (c.groups[g].name.empty())
      throw InputError(f, groups_key, "group " + std::to_string(g) + " has no name");
    for (std::size_t h = 0; h < g; ++h)
      if (c.groups[h].name == c.groups[g].name)
        throw InputError(f, groups_key, "duplicate contact group '" + c.groups[g].name + "'");
    if (c.groups[g].parts.empty())
      throw InputError(f, groups_key, "group '" + c.groups[g].name + "' lists no parts");
  }
  if (c.pairs.empty())
    throw InputError(f, key(from_case ? "pair" : "pairs"),
                     "a penalty contact needs at least one [[contact.pair]]");
  const auto n_groups = static_cast<int>(c.groups.size());
  for (std::size_t p = 0; p < c.pairs.size(); ++p) {
    const auto& pr = c.pairs[p];
    for (int g : {pr.first, pr.second})
      if (g < 0 || g >= n_groups)
        throw InputError(f, pair_key(p),
                         "pair " + std::to_string(p) + " names group " + std::to_string(g) +
                             ", outside 0.." + std::to_string(n_groups - 1));
    for (std::size_t q = 0; q < p; ++q) {
      const auto& o = c.pairs[q];
      if ((o.first == pr.first && o.second == pr.second) ||
          (o.first == pr.second && o.second == pr.first))
        throw InputError(f, pair_key(p),
                         "groups '" + c.groups[static_cast<std::size_t>(pr.first)].name +
                             "' and '" + c.groups[static_cast<std::size_t>(pr.second)].name +
                             "' paired twice");
    }
    check_range(f, from_case ? pair_key(p) + ".friction" : key("pairs.friction"), pr.friction,
                Range::closed(0, 10));
  }
  check_range(f, key("penalty_scale"), c.penalty_scale, Range::open_closed(0, 0.5));
  check_range(f, key("thickness"), c.thickness, Range::non_negative());
  check_range(f, key("damping"), c.damping, Range::closed(0, 1));
  check_range(f, key("search_margin"), c.search_margin, Range::non_negative());
  if (c.search_margin > 0 && !(c.search_margin > c.thickness))
    throw InputError(f, key("search_margin"),
                     "value " + std::to_string(c.search_margin) + " must exceed thickness " +
                         std::to_string(c.thickness) + " (0 selects it automatically)");
  check_range(f, key("edge_tolerance"), c.edge_tolerance, Range::closed(0, 0.5));
  check_range(f, key("max_penetration"), c.max_penetration, Range::open_closed(0, 1));
}

void validate(const TiedContactConfig& c) {
  const std::string& f = c.source_file;
  const bool from_case = !c.key_path.empty();
  auto key = [&](const std::string& field) { return key_of(c.key_path, c.name, field); };
  if (c.name.empty())
    throw InputError(f, from_case ? key("name") : "contact.name", "a tied contact needs a name");
  for (const ContactGroup* g : {&c.slave, &c.master})
    if (g->parts.empty() && c.face_pairs.empty() && !(g == &c.slave && !c.slave_nodes.empty()))
      throw InputError(f,
                       key(g == &c.slave ? (from_case ? "slave_parts" : "slave")
                                         : (from_case ? "master_parts" : "master")),
                       "lists no parts");
  for (int p : c.slave.parts)
    for (int q : c.master.parts)
      if (p == q)
        throw InputError(f, key(from_case ? "master_parts" : "master"),
                         "part index " + std::to_string(p) + " is both slave and master");
  check_range(f, key("penalty_scale"), c.penalty_scale, Range::open_closed(0, 0.5));
  check_range(f, key("search_distance"), c.search_distance, Range::non_negative());
  check_range(f, key("normal_strength"), c.normal_strength, Range::non_negative());
  check_range(f, key("shear_strength"), c.shear_strength, Range::non_negative());
  check_range(f, key("mode_i_energy"), c.mode_i_energy, Range::non_negative());
  check_range(f, key("mode_ii_energy"), c.mode_ii_energy, Range::non_negative());
  check_range(f, key("bk_exponent"), c.bk_exponent, Range::closed(1, 5));
  if (c.mode_i_energy > 0 || c.mode_ii_energy > 0) {
    if (!(c.mode_i_energy > 0) || !(c.mode_ii_energy > 0))
      throw InputError(f, key(c.mode_i_energy > 0 ? "mode_ii_energy" : "mode_i_energy"),
                       "a cohesive tie needs both fracture energies > 0");
    if (!(c.normal_strength > 0) || !(c.shear_strength > 0))
      throw InputError(f, key(c.normal_strength > 0 ? "shear_strength" : "normal_strength"),
                       "a cohesive tie (fracture energies given) needs both strengths > 0");
  }
  for (std::size_t k = 0; k < c.face_pairs.size(); ++k) {
    const auto& p = c.face_pairs[k];
    if (p.slave_face < 0 || p.slave_face > 5 || p.master_face < 0 || p.master_face > 5 ||
        p.slave_hex < 0 || p.master_hex < 0)
      throw InputError(f, key("face_pairs"),
                       "pair " + std::to_string(k + 1) + ": faces must be 0..5 and elements >= 0");
  }
}

}  // namespace ncfsim::fem
