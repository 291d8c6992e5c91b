// Contact surfaces and configuration checks (exact counts, no tolerance):
//  * a block of n x n x n hexahedra has 6 n^2 outer faces, all with outward normals;
//  * a face between two parts of one group is not a surface; between two groups it is on both;
//  * bad configuration values and bad part references throw InputError naming the key.
#include "fem/contact/segment_frame.hpp"
#include "fem/errors.hpp"
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

fem::Mesh two_part_block(int n) {
  fem::Mesh m;
  const int a = m.add_part("left");
  m.add_part("right");
  fem::add_hex_block(m, a, {0, 0, 0}, {1, 1, 1}, {n, n, n});
  fem::ElementSet& hexes = m.elements(fem::ElementKind::Hex8);
  for (std::size_t e = 0; e < hexes.size(); ++e) {
    double cx = 0;
    for (auto v : hexes.nodes(e)) cx += m.coords[3 * static_cast<std::size_t>(v)] / 8;
    hexes.part[e] = cx < 0.5 ? 0 : 1;
  }
  m.fill_default_user_ids();
  return m;
}

}  // namespace

TEST(ContactSurface, OuterFacesOfABlockPointOutwards) {
  const fem::Mesh m = two_part_block(4);
  const auto s =
      fem::extract_contact_surface(m, {{"all", {0, 1}}}, m.coords.data(), "", "contact.t");
  ASSERT_EQ(s.n_segments(), 6u * 16u);
  EXPECT_EQ(s.n_nodes(), 5u * 5u * 5u - 3u * 3u * 3u);
  double area = 0;
  for (std::size_t q = 0; q < s.n_segments(); ++q) {
    double p[4][3];
    fem::gather_segment(m.coords.data(), &s.seg_nodes[4 * q], p);
    fem::SegmentFrame f;
    fem::segment_frame(p, 0, f);
    // Outward: the normal points away from the block centre.
    const double out = (f.c[0] - 0.5) * f.n[0] + (f.c[1] - 0.5) * f.n[1] + (f.c[2] - 0.5) * f.n[2];
    EXPECT_GT(out, 0.4) << "segment " << q;
    EXPECT_NEAR(s.seg_elem_thickness[q], 0.25, 1e-12);
  }
  for (double a : s.node_area) area += a;
  EXPECT_NEAR(area, 6.0, 1e-12) << "tributary areas add up to the surface area";
}

TEST(ContactSurface, FacesBetweenGroupsBelongToBothSurfaces) {
  const fem::Mesh m = two_part_block(4);
  const auto s = fem::extract_contact_surface(m, {{"left", {0}}, {"right", {1}}}, m.coords.data(),
                                              "", "contact.t");
  EXPECT_EQ(s.n_segments(), 2u * (6u * 16u / 2u + 16u));
  // Each half (2 x 4 x 4 hexahedra) has 3*5*5 - 1*3*3 surface nodes; the 25 nodes of the shared
  // plane appear once per group.
  EXPECT_EQ(s.n_nodes(), 2u * (3u * 5u * 5u - 1u * 3u * 3u));
}

// The memory estimate counts a surface without building it (contact_surface_size): the same
// segments and surface nodes as extract_contact_surface, with and without the inner faces that
// erosion may uncover, for one group and for two.
TEST(ContactSurface, SizeCountedWithoutBuildingMatchesTheBuiltSurface) {
  const fem::Mesh m = two_part_block(4);
  for (const bool interior : {false, true})
    for (const std::vector<fem::ContactGroup>& groups :
         {std::vector<fem::ContactGroup>{{"all", {0, 1}}},
          std::vector<fem::ContactGroup>{{"left", {0}}, {"right", {1}}}}) {
      const auto built =
          fem::extract_contact_surface(m, groups, m.coords.data(), "", "contact.t", interior);
      const auto size = fem::contact_surface_size(m, groups, interior);
      EXPECT_EQ(size.segments, static_cast<double>(built.n_segments()))
          << groups.size() << " groups, inner faces " << interior;
      EXPECT_EQ(size.nodes, static_cast<double>(built.n_nodes()))
          << groups.size() << " groups, inner faces " << interior;
    }
  // Inner faces once from each side: 6 n^2 outer + 2 * 3 n^2 (n - 1) inner for n = 4.
  EXPECT_EQ(fem::contact_surface_size(m, {{"all", {0, 1}}}, true).segments,
            6.0 * 16 + 2.0 * 3 * 16 * 3);
}

TEST(ContactSurface, SegmentProjectionIsExactOnAParallelogram) {
  const double p[4][3] = {{0, 0, 0}, {2, 0, 0}, {3, 1, 0}, {1, 1, 0}};
  fem::SegmentFrame f;
  fem::segment_frame(p, 0, f);
  // x(xi, eta) = c + xi a1 + eta a2 with c = (1.5, 0.5), a1 = (1, 0), a2 = (0.5, 0.5)
  const auto pr = fem::project_on_segment(f, 1.5 + 0.3 + 0.5 * -0.4, 0.5 + 0.5 * -0.4, 0.25);
  EXPECT_NEAR(pr.xi, 0.3, 1e-14);
  EXPECT_NEAR(pr.eta, -0.4, 1e-14);
  EXPECT_NEAR(pr.gap, 0.25, 1e-14);
}

TEST(ContactConfig, BadValuesThrowInputErrorNamingTheKey) {
  auto base = [] {
    fem::PenaltyContactConfig c;
    c.name = "plies";
    c.groups = {{"a", {0}}, {"b", {1}}};
    c.pairs = {{0, 1, 0.2}};
    return c;
  };
  EXPECT_NO_THROW(fem::validate(base()));
  auto expect_key = [](const fem::PenaltyContactConfig& c, const std::string& key) {
    try {
      fem::validate(c);
      ADD_FAILURE() << "no error for " << key;
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  auto c = base();
  c.penalty_scale = 0;
  expect_key(c, "contact.plies.penalty_scale");
  c = base();
  c.pairs[0].friction = -0.1;
  expect_key(c, "contact.plies.pairs.friction");
  c = base();
  c.pairs[0].second = 2;
  expect_key(c, "contact.plies.pairs");
  c = base();
  c.thickness = 1e-3;
  c.search_margin = 0.5e-3;
  expect_key(c, "contact.plies.search_margin");
  c = base();
  c.max_penetration = 1.5;
  expect_key(c, "contact.plies.max_penetration");
  c = base();
  c.groups[1].parts.clear();
  expect_key(c, "contact.plies.groups");

  fem::TiedContactConfig t;
  t.name = "glue";
  t.slave = {"a", {0}};
  t.master = {"b", {1}};
  EXPECT_NO_THROW(fem::validate(t));
  t.normal_strength = -1;
  EXPECT_THROW(fem::validate(t), InputError);
}

TEST(ContactConfig, PartsAreCheckedAgainstTheMesh) {
  const fem::Mesh m = two_part_block(2);
  EXPECT_THROW(fem::extract_contact_surface(m, {{"a", {0}}, {"b", {7}}}, m.coords.data(), "", "c"),
               InputError);
  EXPECT_THROW(
      fem::extract_contact_surface(m, {{"a", {0}}, {"b", {0, 1}}}, m.coords.data(), "", "c"),
      InputError);
}

TEST(ContactSurface, FrameBlockKernelMatchesTheSingleSegmentFrame) {
  // A warped, skewed quadrilateral in every lane, shifted lane by lane: same frame to 1e-14.
  double p[4][3][fem::kFrameLanes];
  double depth[fem::kFrameLanes];
  const double q0[4][3] = {{0, 0, 0}, {2, 0.1, 0.05}, {2.5, 1.2, -0.1}, {0.2, 0.9, 0.02}};
  for (int l = 0; l < fem::kFrameLanes; ++l) {
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) p[a][k][l] = q0[a][k] + 0.1 * l * (k + 1);
    depth[l] = 0.01 * l;
  }
  fem::SegmentFrameBlock fb;
  fem::segment_frames(p, depth, fb);
  for (int l = 0; l < fem::kFrameLanes; ++l) {
    double q[4][3];
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) q[a][k] = p[a][k][l];
    fem::SegmentFrame f;
    fem::segment_frame(q, depth[l], f);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(fb.c[k][l], f.c[k], 1e-14);
      EXPECT_NEAR(fb.n[k][l], f.n[k], 1e-14);
      EXPECT_NEAR(fb.e1[k][l], f.e1[k], 1e-14);
      EXPECT_NEAR(fb.e2[k][l], f.e2[k], 1e-14);
    }
    EXPECT_NEAR(fb.hn[l], f.hn, 1e-14);
    const auto a = fem::project_on_segment(f, 1.0, 0.5, 0.3);
    const auto b = fem::project_on_segment(fb, l, 1.0, 0.5, 0.3);
    EXPECT_NEAR(a.xi, b.xi, 1e-14);
    EXPECT_NEAR(a.gap, b.gap, 1e-14);
  }
}
