// docs/tour.md, the newcomer's reading path, stays true to the code (issue #44): every
// `path:symbol` it names is a file of the repository that defines that symbol (a function or
// method followed by its parameter list), and every `path` it names exists.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
const fs::path kSource = NCFSIM_SOURCE_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string escape(const std::string& s) {
  static const std::regex special(R"([.^$|()\[\]{}*+?\\])");
  return std::regex_replace(s, special, R"(\$&)");
}

TEST(DocsTour, EveryFileAndFunctionItNamesExists) {
  const std::string tour = slurp(kSource / "docs/tour.md");
  ASSERT_FALSE(tour.empty()) << "docs/tour.md is missing";
  std::size_t lines = 1;
  for (char c : tour) lines += c == '\n';
  EXPECT_LE(lines, 150u) << "the tour is meant to be read in one sitting";
  const std::regex named(R"(`([A-Za-z0-9_./-]+\.(?:cpp|hpp|toml|md))(?::([A-Za-z0-9_:~]+))?`)");
  std::size_t files = 0, symbols = 0;
  for (auto it = std::sregex_iterator(tour.begin(), tour.end(), named);
       it != std::sregex_iterator(); ++it) {
    const std::string file = (*it)[1], symbol = (*it)[2];
    ++files;
    ASSERT_TRUE(fs::exists(kSource / file)) << "docs/tour.md names " << file;
    if (symbol.empty()) continue;
    ++symbols;
    const std::string text = slurp(kSource / file);
    // A definition: the (qualified) name, then its parameter list; `main` as `int main(`.
    const std::regex defined((symbol == "main" ? std::string("int main") : escape(symbol)) +
                             R"(\s*\()");
    EXPECT_TRUE(std::regex_search(text, defined)) << "docs/tour.md names " << file << ":" << symbol
                                                  << ", which " << file << " does not define";
  }
  EXPECT_GE(files, 30u);
  EXPECT_GE(symbols, 25u);
}

}  // namespace
