#include "fem/contact/contact_config.hpp"

#include <cmath>
#include <sstream>

#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {

std::string key_of(const std::string& name, const std::string& field) {
  return "contact." + name + "." + field;
}

void check_range(const std::string& file, const std::string& key, double value, double lo,
                 double hi, bool lo_open, bool hi_open = false) {
  const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) &&
                  (hi_open ? value < hi : value <= hi);
  if (ok) return;
  std::ostringstream os;
  os << "value " << value << " outside " << (lo_open ? "(" : "[") << lo << ", ";
  if (std::isinf(hi))
    os << "inf)";
  else
    os << hi << (hi_open ? ")" : "]");
  throw InputError(file, key, os.str());
}

constexpr double kInf = INFINITY;

}  // namespace

void validate(const PenaltyContactConfig& c) {
  const std::string& f = c.source_file;
  if (c.name.empty()) throw InputError(f, "contact.name", "a contact needs a name");
  if (c.groups.empty()) throw InputError(f, key_of(c.name, "groups"), "no contact groups given");
  for (std::size_t g = 0; g < c.groups.size(); ++g) {
    if (c.groups[g].name.empty())
      throw InputError(f, key_of(c.name, "groups"), "group " + std::to_string(g) + " has no name");
    for (std::size_t h = 0; h < g; ++h)
      if (c.groups[h].name == c.groups[g].name)
        throw InputError(f, key_of(c.name, "groups"),
                         "group name '" + c.groups[g].name + "' used twice");
    if (c.groups[g].parts.empty())
      throw InputError(f, key_of(c.name, "groups"),
                       "group '" + c.groups[g].name + "' lists no parts");
  }
  if (c.pairs.empty()) throw InputError(f, key_of(c.name, "pairs"), "no contact pairs given");
  const auto n_groups = static_cast<int>(c.groups.size());
  for (std::size_t p = 0; p < c.pairs.size(); ++p) {
    const auto& pr = c.pairs[p];
    for (int g : {pr.first, pr.second})
      if (g < 0 || g >= n_groups)
        throw InputError(f, key_of(c.name, "pairs"),
                         "pair " + std::to_string(p) + " names group " + std::to_string(g) +
                             ", outside 0.." + std::to_string(n_groups - 1));
    for (std::size_t q = 0; q < p; ++q) {
      const auto& o = c.pairs[q];
      if ((o.first == pr.first && o.second == pr.second) ||
          (o.first == pr.second && o.second == pr.first))
        throw InputError(f, key_of(c.name, "pairs"),
                         "groups '" + c.groups[static_cast<std::size_t>(pr.first)].name +
                             "' and '" + c.groups[static_cast<std::size_t>(pr.second)].name +
                             "' paired twice");
    }
    check_range(f, key_of(c.name, "pairs.friction"), pr.friction, 0, 10, false);
  }
  check_range(f, key_of(c.name, "penalty_scale"), c.penalty_scale, 0, 0.5, true);
  check_range(f, key_of(c.name, "thickness"), c.thickness, 0, kInf, false, true);
  check_range(f, key_of(c.name, "damping"), c.damping, 0, 1, false);
  check_range(f, key_of(c.name, "search_margin"), c.search_margin, 0, kInf, false, true);
  if (c.search_margin > 0 && !(c.search_margin > c.thickness))
    throw InputError(f, key_of(c.name, "search_margin"),
                     "value " + std::to_string(c.search_margin) + " must exceed thickness " +
                         std::to_string(c.thickness) + " (0 selects it automatically)");
  check_range(f, key_of(c.name, "edge_tolerance"), c.edge_tolerance, 0, 0.5, false);
  check_range(f, key_of(c.name, "max_penetration"), c.max_penetration, 0, 1, true);
}

void validate(const TiedContactConfig& c) {
  const std::string& f = c.source_file;
  if (c.name.empty()) throw InputError(f, "contact.name", "a tied contact needs a name");
  for (const ContactGroup* g : {&c.slave, &c.master})
    if (g->parts.empty())
      throw InputError(f, key_of(c.name, g == &c.slave ? "slave" : "master"), "lists no parts");
  for (int p : c.slave.parts)
    for (int q : c.master.parts)
      if (p == q)
        throw InputError(f, key_of(c.name, "master"),
                         "part index " + std::to_string(p) + " is both slave and master");
  check_range(f, key_of(c.name, "penalty_scale"), c.penalty_scale, 0, 0.5, true);
  check_range(f, key_of(c.name, "search_distance"), c.search_distance, 0, kInf, false, true);
  check_range(f, key_of(c.name, "normal_strength"), c.normal_strength, 0, kInf, false, true);
  check_range(f, key_of(c.name, "shear_strength"), c.shear_strength, 0, kInf, false, true);
}

}  // namespace ncfsim::fem
