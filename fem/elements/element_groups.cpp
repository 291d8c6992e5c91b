// The one place that maps an element kind to its group (a new kind adds a case here).
#include "fem/elements/element_group.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::fem {

std::unique_ptr<ElementGroup> make_hex8_group(const Model&, const ElementSet&, int,
                                              const std::vector<std::size_t>&, const double*);
std::unique_ptr<ElementGroup> make_bar2_group(const Model&, const ElementSet&, int,
                                              const std::vector<std::size_t>&, const double*);

std::unique_ptr<ElementGroup> make_quad4_group(const Model&, const ElementSet&, int,
                                               const std::vector<std::size_t>&, const double*);

std::unique_ptr<ElementGroup> make_element_group(const Model& model, const ElementSet& set,
                                                 int part, const std::vector<std::size_t>& elements,
                                                 const double* x_ref) {
  switch (set.kind) {
    case ElementKind::Hex8:
      return make_hex8_group(model, set, part, elements, x_ref);
    case ElementKind::Bar2:
      return make_bar2_group(model, set, part, elements, x_ref);
    case ElementKind::Quad4:
      return make_quad4_group(model, set, part, elements, x_ref);
  }
  return nullptr;
}

}  // namespace ncfsim::fem
