#pragma once
#include <string>
// A flat 60 x 60 mm +-45 NCF blanket (the CI mesh: one element across a tow, two pitches long)
// with the default dry-tow law and a linear stitch: the body of a case file, without [case]; tests
// append their [case], [time], [output] and probes.
namespace ncfsim::test {

inline constexpr const char* kFlatBlanketBody = R"(
[mesh]
[[mesh.fabric]]
name = "ncf"
origin = [0.0, 0.0, 0.0]
size = [0.06, 0.06]
ply_angles_deg = [45.0, -45.0]
elements_across_tow = 1
element_length = 6.64e-3
tow_material = "dry_tow"
stitch_law_I = "stitch"
stitch_law_Lambda = "stitch"
[[material]]
name = "dry_tow"
type = "tow_biphase"
density = 1080.0
E11f = 0.07e9
E11m = 1.0e6
E22m = 0.5e6
E33m = 0.5e6
G12m = 0.1e6
compaction_modulus = 2.0e6
[[bar_law]]
name = "stitch"
type = "tabulated"
tension_only = true
linear_density = 7.6e-6
strain = [0.0, 0.1]
force = [0.0, 2.0]
)";

/// The blanket run for a few cycles (nearly undeformed, no figures): a drape result for the
/// stages downstream (transfer, crush) to start from.
inline const std::string kFlatBlanketBriefRun =
    std::string("[case]\nname = \"flat_blanket\"\n") + kFlatBlanketBody + R"(
[time]
end_time = 2e-6
[output]
figures = false
)";

}  // namespace ncfsim::test
