#pragma once
// Is a model small enough for this machine? Estimated from the counts a case asks for, before the
// mesh is generated: a block of 1000^3 hexahedra or a fabric meshed at 1e-9 m is bad input naming
// its key, not a std::bad_alloc (or the kernel's OOM killer) minutes later.
#include <string>

#include "fem/memory_estimate.hpp"  // available_memory_bytes, bytes_text

namespace ncfsim::fem {

/// Bytes an explicit model holds (nodal state vectors, element state, contact surfaces), per
/// node, hexahedron and bar: a rough bound for the guard below, before anything is meshed. The
/// estimate a run checks, by element kind, contact, tool and output, is estimate_memory
/// (fem/memory_estimate.hpp), made once the whole case is read.
double estimated_model_bytes(double n_nodes, double n_hex, double n_bars);

/// Throws InputError(file, key) when a model of the counts given (the whole model so far plus
/// what `key` adds) would need more than 80 % of the memory available, naming the estimate.
void require_model_fits(const std::string& file, const std::string& key, double n_nodes,
                        double n_hex, double n_bars);

}  // namespace ncfsim::fem
