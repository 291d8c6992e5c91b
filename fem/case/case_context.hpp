#pragma once
// What the module case readers share while one case file is read: the reading context (the
// document, the model being built, the parts and their origin, the names of materials and bar
// laws, named node sets a selector can pick) and the registry of types (material type -> the
// reader of its keys). One context per load; nothing global. docs/architecture.md.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fem/case/toml_reader.hpp"
#include "fem/model.hpp"

namespace ncfsim::fem {

/// Reads the type-specific keys of one [[material]] table (`name` and `density` are read already).
/// May throw std::invalid_argument (a law's own consistency check): reported at `type`.
using MaterialReader =
    std::function<std::unique_ptr<SolidMaterial>(const TableReader& t, const std::string& name, double density)>;
/// Reads the type-specific keys of one [[membrane_law]] table (`name` is read already).
using MembraneLawReader =
    std::function<std::unique_ptr<MembraneLaw>(const TableReader& t, const std::string& name)>;

/// Material type -> reader. Each module registers its own types by an explicit call
/// (fem::register_fem_case_types, drape::register_drape_case_types), made by the case
/// orchestration before reading; the order of registration is the order the types are listed in.
class CaseTypeRegistry {
 public:
  /// Throws std::logic_error when `type` is registered already.
  void add_material_type(std::string type, MaterialReader reader);
  std::vector<std::string> material_types() const;
  /// Reads `type` (one of the registered types), `density` (> 0) and dispatches to the type's reader.
  std::unique_ptr<SolidMaterial> read_material(const TableReader& t, const std::string& name) const;
  /// Membrane laws of shells ([[membrane_law]] type = ...), registered by the module that has
  /// them (drape: "fabric").
  void add_membrane_law_type(std::string type, MembraneLawReader reader);
  std::unique_ptr<MembraneLaw> read_membrane_law(const TableReader& t, const std::string& name) const;

 private:
  std::vector<std::pair<std::string, MaterialReader>> materials_;
  std::vector<std::pair<std::string, MembraneLawReader>> membrane_laws_;
};

/// fem's own material types: elastic_isotropic, elastic_orthotropic.
void register_fem_case_types(CaseTypeRegistry& registry);

/// How a part of the mesh gets its properties.
enum class PartKind { Solid, Bar, Shell };

/// A selector key of node selections that names a node set a module made
/// (`tow_end_pins = "fabric name"`).
struct NamedNodeSets {
  std::string owner;  // the section that makes the sets, for messages: "[[mesh.fabric]]"
  std::map<std::string, std::vector<std::int32_t>> sets;  // name -> node indices (renumbered)
};

/// The state of reading one case file, passed to every module reader.
struct CaseReadContext {
  CaseReadContext(CaseDocument& doc, Model& model, const CaseTypeRegistry& types)
      : doc(doc), root(doc, doc.root(), ""), file(doc.file().string()), model(model), types(types) {}

  CaseDocument& doc;
  TableReader root;
  std::string file;  // for messages
  Model& model;
  const CaseTypeRegistry& types;

  std::string resolution = "default";  // [mesh].resolution: coarse | default | fine
  double resolution_factor = 1.0;      // 0.5 | 1 | 2

  std::map<std::string, PartKind> part_kind;         // part name -> what its elements are
  std::map<std::string, std::string> generated_parts;  // part name -> section that gives its properties
  std::map<std::string, int> materials, bar_laws;    // name -> index into model.materials / bar_laws
  std::map<std::string, int> membrane_laws;          // name -> index into model.membrane_laws
  std::vector<char> part_defined;                    // per part: properties given

  std::map<std::string, NamedNodeSets> node_sets;  // selector key -> named sets
  std::vector<double> frame_final_angles;           // per picture frame: final shear angle, rad
  std::vector<double> frame_fabric_length;          // per picture frame: side of the fabric, m
};

}  // namespace ncfsim::fem
