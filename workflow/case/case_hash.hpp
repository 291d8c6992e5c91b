#pragma once
// Hashes of a case's inputs: the MD5 of the workflow's stage inputs (workflow_stage.cpp) and of a
// checkpoint's case (workflow/run/run_checkpoint.cpp).
#include <toml++/toml.h>
#include <vtksys/MD5.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace ncfsim::workflow {

class Md5 {
 public:
  Md5() : h_(vtksysMD5_New()) { vtksysMD5_Initialize(h_); }
  ~Md5() { vtksysMD5_Delete(h_); }
  Md5(const Md5&) = delete;
  Md5& operator=(const Md5&) = delete;
  void add(const std::string& s) {
    // Length first: ("ab", "c") and ("a", "bc") must differ.
    const std::string len = std::to_string(s.size()) + ":";
    vtksysMD5_Append(h_, reinterpret_cast<const unsigned char*>(len.data()),
                     static_cast<int>(len.size()));
    vtksysMD5_Append(h_, reinterpret_cast<const unsigned char*>(s.data()),
                     static_cast<int>(s.size()));
  }
  /// The bytes of a file, as add() of its content would take them, read in pieces (an upstream
  /// results.h5 may be gigabytes). False when it cannot be read.
  bool add_file(const std::filesystem::path& file) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    std::ifstream in(file, std::ios::binary);
    if (ec || !in) return false;
    const std::string len = std::to_string(size) + ":";
    vtksysMD5_Append(h_, reinterpret_cast<const unsigned char*>(len.data()),
                     static_cast<int>(len.size()));
    std::vector<char> buf(1 << 20);
    std::uintmax_t left = size;
    while (left > 0 && in) {
      in.read(buf.data(), static_cast<std::streamsize>(std::min<std::uintmax_t>(buf.size(), left)));
      const auto got = static_cast<std::uintmax_t>(in.gcount());
      if (got == 0) break;
      vtksysMD5_Append(h_, reinterpret_cast<const unsigned char*>(buf.data()),
                       static_cast<int>(got));
      left -= got;
    }
    return left == 0;
  }
  std::string hex() {
    char out[33] = {};
    vtksysMD5_FinalizeHex(h_, out);
    return std::string(out, 32);
  }

 private:
  vtksysMD5* h_;
};

/// String values of a TOML tree (any depth), with their key paths.
inline void string_values(const toml::node& n, const std::string& path,
                          std::vector<std::pair<std::string, std::string>>& out) {
  if (const auto* t = n.as_table()) {
    for (const auto& [k, v] : *t)
      string_values(v, path.empty() ? std::string(k.str()) : path + "." + std::string(k.str()),
                    out);
  } else if (const auto* a = n.as_array()) {
    for (std::size_t i = 0; i < a->size(); ++i)
      string_values(*a->get(i), path + "[" + std::to_string(i) + "]", out);
  } else if (const auto* s = n.as_string()) {
    out.emplace_back(path, s->get());
  }
}

/// The resolved case (`root`: a CaseDocument's, with its base, includes and overrides) as the text
/// the hashes cover, less the run-control keys that do not change what a completed run holds
/// (time.max_cycles, output.checkpoint_*): a stage stopped by its cycle limit resumes with the
/// same hash.
inline std::string hashed_case_text(toml::table root) {
  if (auto* t = root["time"].as_table()) t->erase("max_cycles");
  if (auto* o = root["output"].as_table()) {
    o->erase("checkpoint_interval");
    o->erase("checkpoint_every_cycles");
  }
  std::ostringstream resolved;
  resolved << root;
  return resolved.str();
}

}  // namespace ncfsim::workflow
