// Fuzzed case files through `ncfsim check` (issue #23): every case file under cases/ and
// tests/cases/ (copied with their folders, so relative paths still resolve) is mutated
// deterministically, key by key (deleted; set to 0, -1, nan, inf, 1e30, a huge count, a string of
// garbage, an empty array, true) and as a whole (truncated, garbage bytes inserted, emptied);
// at least 2000 variants. Each is checked under a 6 GB address-space limit and a 120 s time
// limit and must end with exit code 0 (still a valid case) or 2 (bad input naming the key):
// never a crash, a signal, an out-of-memory exit (1) or a hang. The variants that fail are listed
// with their mutation and the output, and kept under the test's folder to rerun by hand.
// The unmutated files are checked first, under the same rules. A file whose model has more than
// 50 000 nodes (the paper-size meshes: ~5 s a check against ~0.3 s) has 2 keys mutated, the
// others 4: about 2500 variants. A check costs ~0.2 s of CPU alone, nearly all of it the start of
// the process (the ~170 shared libraries of PETSc and VTK) and of MPI: the variants are checked
// 16 to an `ncfsim check` (each file checked as alone, its exit code on its own line), and those
// of a process that crashed, hung or ran out of memory again one to a process.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <map>
#include <thread>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

constexpr std::size_t kLeavesPerFile = 4;       // keys mutated per file (spread over the file)
constexpr std::size_t kLeavesPerLargeFile = 2;  // ... per file of a paper-size model
constexpr std::size_t kLargeModelNodes = 50000;
constexpr int kParallel = 2;
constexpr double kTimeLimit = 120;            // s per variant
constexpr rlim_t kAddressLimit = 6ull << 30;  // bytes

struct Variant {
  fs::path file;
  std::string what;  // the mutation, for the report
};

// Key paths of the leaves of a TOML tree (arrays of tables are descended; plain arrays are leaves).
void leaves(const toml::node& n, std::vector<toml::path>& out, const toml::path& here) {
  if (const auto* t = n.as_table()) {
    for (const auto& [k, v] : *t) leaves(v, out, here + toml::path(std::string(k.str())));
  } else if (const auto* a = n.as_array(); a && a->is_array_of_tables()) {
    for (std::size_t i = 0; i < a->size(); ++i) {
      std::string index = std::to_string(i);  // "[" + ... trips GCC 12's -Wrestrict
      index.insert(index.begin(), '[');
      index.push_back(']');
      leaves(*a->get(i), out, here + toml::path(index));
    }
  } else {
    out.push_back(here);
  }
}

// The parent table (or array) of a leaf and its last component.
bool mutate_leaf(toml::table& root, const toml::path& p, int kind) {
  toml::node* parent = p.parent().empty() ? &root : root.at_path(p.parent()).node();
  if (!parent) return false;
  const auto& last = p[p.size() - 1];
  auto value = [&]() -> std::unique_ptr<toml::node> {
    switch (kind) {
      case 1:
        return std::make_unique<toml::value<std::int64_t>>(0);
      case 2:
        return std::make_unique<toml::value<std::int64_t>>(-1);
      case 3:
        return std::make_unique<toml::value<double>>(std::numeric_limits<double>::quiet_NaN());
      case 4:
        return std::make_unique<toml::value<double>>(std::numeric_limits<double>::infinity());
      case 5:
        return std::make_unique<toml::value<double>>(1e30);
      case 6:
        return std::make_unique<toml::value<std::int64_t>>(2000000000);
      case 7:
        return std::make_unique<toml::value<std::string>>("\x01garbage\xff");
      case 8:
        return std::make_unique<toml::array>();
      default:
        return std::make_unique<toml::value<bool>>(true);
    }
  };
  if (auto* t = parent->as_table(); t && last.type() == toml::path_component_type::key) {
    if (kind == 0) return t->erase(last.key()) > 0;
    auto v = value();
    t->insert_or_assign(last.key(), std::move(*v));
    return true;
  }
  if (auto* a = parent->as_array(); a && last.type() == toml::path_component_type::array_index) {
    if (last.index() >= a->size()) return false;
    a->erase(a->begin() + static_cast<std::ptrdiff_t>(last.index()));
    if (kind != 0) {
      auto v = value();
      a->insert(a->begin() + static_cast<std::ptrdiff_t>(last.index()), std::move(*v));
    }
    return true;
  }
  return false;
}

const char* kKindNames[] = {"deleted",        "0",  "-1",  "nan", "inf", "1e30", "2e9",
                            "garbage string", "[]", "true"};

std::vector<Variant> make_variants(const fs::path& root, const std::vector<fs::path>& cases,
                                   const std::vector<bool>& large) {
  std::vector<Variant> out;
  std::size_t serial = 0;
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const fs::path& file = cases[c];
    const std::string text = slurp(file);
    auto name = [&](const std::string& tag) {
      return file.parent_path() / ("fuzz_" + std::to_string(serial++) + "_" + tag + ".toml");
    };
    auto write = [&](const fs::path& p, const std::string& t, std::string what) {
      std::ofstream(p, std::ios::binary) << t;
      out.push_back({p, fs::relative(file, root).string() + ": " + what});
    };
    write(name("truncated"), text.substr(0, text.size() / 2), "truncated at half");
    std::string garbled = text;
    static const std::string junk("\x00\xfe\x01]]]=[[\"\n", 10);
    garbled.insert(garbled.size() / 3, junk);
    write(name("garbled"), garbled, "garbage bytes at a third");
    write(name("empty"), "", "emptied");
    toml::table doc;
    try {
      doc = toml::parse(text);
    } catch (const toml::parse_error&) {
      continue;
    }
    std::vector<toml::path> paths;
    leaves(doc, paths, toml::path());
    const std::size_t n = std::min(large[c] ? kLeavesPerLargeFile : kLeavesPerFile, paths.size());
    for (std::size_t i = 0; i < n; ++i) {
      const toml::path& p = paths[i * paths.size() / n];
      for (int kind = 0; kind < 10; ++kind) {
        toml::table copy = doc;
        if (!mutate_leaf(copy, p, kind)) continue;
        std::ostringstream os;
        os << copy;
        write(name("key"), os.str(), std::string(p.str()) + " " + kKindNames[kind]);
      }
    }
  }
  return out;
}

// `ncfsim check` of `files` in one process (a check costs mostly the start of the process and of
// MPI: ~0.2 s of CPU against a few ms for the case itself), its output in `log`.
pid_t start_check(const std::vector<fs::path>& files, const fs::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    rlimit as{kAddressLimit, kAddressLimit};
    setrlimit(RLIMIT_AS, &as);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    ::unsetenv("DISPLAY");
    // No Open MPI daemon per check (a singleton forks one: ~0.2 s more per check here).
    ::setenv("OMPI_MCA_ess_singleton_isolated", "1", 1);
    use_own_mpi_session_base();
    std::vector<std::string> args = {kExe.string(), "check"};
    for (const auto& f : files) args.push_back(f.string());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Every variant through `ncfsim check`, kBatch files to a process, kParallel processes at a time:
// its exit code (-2: timed out) and, where it is neither 0 nor 2, its output. A process checking
// several files ends each with "check FILE: ... (exit N)", which gives the file its code and its
// share of the output; the files a process did not get to (it crashed, was killed for memory or
// timed out) are checked again one to a process, so that what failed is the file's own exit.
// The log of a variant that passes is removed with it unless `keep` (the originals).
struct Outcome {
  int code = 0;
  std::string log;
};
constexpr std::size_t kBatch = 16;

std::vector<Outcome> check_all(const std::vector<Variant>& variants, bool keep,
                               std::size_t batch = kBatch) {
  std::vector<Outcome> out(variants.size());
  struct Running {
    pid_t pid;
    std::vector<std::size_t> ks;
    fs::path log;
    std::chrono::steady_clock::time_point start;
  };
  std::vector<Running> running;
  std::vector<std::vector<std::size_t>> todo;  // the batches, in order
  for (std::size_t k = 0; k < variants.size(); k += batch) {
    todo.emplace_back();
    for (std::size_t j = k; j < std::min(variants.size(), k + batch); ++j) todo.back().push_back(j);
  }
  std::size_t next = 0;
  auto finish = [&](std::size_t k, int code, std::string log) {
    out[k].code = code;
    const bool failed = code != 0 && code != 2;
    if (failed || keep) out[k].log = std::move(log);
    if (!failed && !keep) fs::remove(variants[k].file);
  };
  while (next < todo.size() || !running.empty()) {
    while (next < todo.size() && running.size() < static_cast<std::size_t>(kParallel)) {
      const auto& ks = todo[next++];
      std::vector<fs::path> files;
      for (const std::size_t k : ks) files.push_back(variants[k].file);
      const fs::path log = variants[ks.front()].file.string() + ".log";
      running.push_back({start_check(files, log), ks, log, std::chrono::steady_clock::now()});
    }
    for (std::size_t r = 0; r < running.size();) {
      int status = 0;
      const pid_t done = waitpid(running[r].pid, &status, WNOHANG);
      const double age =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - running[r].start)
              .count();
      if (done == 0 && age < kTimeLimit) {
        ++r;
        continue;
      }
      Running job = std::move(running[r]);
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(r));
      int code = -2;
      if (done == 0) {
        kill(job.pid, SIGKILL);
        waitpid(job.pid, &status, 0);
      } else {
        code = exit_code(status);
      }
      remove_mpi_session_base(job.pid);
      const std::string log = slurp(job.log);
      fs::remove(job.log);
      if (job.ks.size() == 1) {
        finish(job.ks.front(), code, log);
        continue;
      }
      // Each file's share of the log ends with its own line.
      std::size_t from = 0;
      std::vector<std::size_t> again;
      for (const std::size_t k : job.ks) {
        const std::string mark = "check " + variants[k].file.string() + ": ";
        const std::size_t at = log.find(mark, from);
        const std::size_t code_at = at == std::string::npos ? at : log.find("(exit ", at);
        const std::size_t eol = code_at == std::string::npos ? code_at : log.find('\n', code_at);
        if (eol == std::string::npos) {
          again.push_back(k);
          continue;
        }
        finish(k, std::stoi(log.substr(code_at + 6)), log.substr(from, eol + 1 - from));
        from = eol + 1;
      }
      for (const std::size_t k : again) todo.push_back({k});
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return out;
}

// The largest node count a check reports ("..., 318603 nodes, ..."; a workflow lists its stages').
std::size_t reported_nodes(const std::string& log) {
  std::size_t most = 0;
  for (std::size_t at = log.find(" nodes,"); at != std::string::npos;
       at = log.find(" nodes,", at + 1)) {
    std::size_t b = at;
    while (b > 0 && std::isdigit(static_cast<unsigned char>(log[b - 1]))) --b;
    if (b < at) most = std::max<std::size_t>(most, std::stoull(log.substr(b, at - b)));
  }
  return most;
}

// Each outcome counted by its exit code; one failure per exit other than 0 and 2.
void report_failures(const std::vector<Variant>& variants, const std::vector<Outcome>& outcomes,
                     std::map<int, std::size_t>& by_code) {
  for (std::size_t k = 0; k < variants.size(); ++k) {
    const int code = outcomes[k].code;
    ++by_code[code];
    if (code == 0 || code == 2) continue;
    ADD_FAILURE() << variants[k].what << " -> "
                  << (code == -2 ? std::string("timed out") : "exit " + std::to_string(code))
                  << " (" << variants[k].file.string() << "): " << outcomes[k].log.substr(0, 400);
  }
}

// Processes that parse but cannot run as meant (issue #45): each must be refused, exit 2.
std::vector<Variant> process_variants(const fs::path& root) {
  struct Change {
    const char* file;
    const char* key;
    toml::node_type type;
    double value;
  };
  const Change changes[] = {
      {"cases/hemisphere/crush.toml", "tool[0].velocity", toml::node_type::array, 0.0},
      {"cases/hemisphere/crush.toml", "time.history_interval", toml::node_type::floating_point,
       1e-3},
      {"cases/hemisphere/crush.toml", "time.end_time", toml::node_type::floating_point, 1e-5},
      {"cases/hemisphere/fishnet.toml", "ring.height", toml::node_type::floating_point, 0.5},
  };
  std::vector<Variant> out;
  int k = 0;
  for (const auto& c : changes) {
    toml::table t = toml::parse_file((root / c.file).string());
    auto node = t.at_path(c.key);
    if (c.type == toml::node_type::array && node.as_array())
      *node.as_array() = toml::array{c.value, c.value, c.value};
    else if (node.as_floating_point())
      *node.as_floating_point() = c.value;
    else
      ADD_FAILURE() << c.file << ": no key " << c.key << " to change";
    const fs::path f =
        (root / c.file).parent_path() / ("process_variant_" + std::to_string(k++) + ".toml");
    std::ofstream(f) << t << "\n";
    out.push_back({f, std::string(c.file) + ": " + c.key + " = " + std::to_string(c.value)});
  }
  return out;
}

TEST(CliFuzz, MutatedCaseFilesEndWithExitZeroOrTwo) {
  const fs::path root = fresh_dir("case_fuzz");
  fs::create_directories(root);
  fs::copy(kSource / "cases", root / "cases", fs::copy_options::recursive);
  fs::create_directories(root / "tests");
  fs::copy(kSource / "tests/cases", root / "tests/cases", fs::copy_options::recursive);
  std::vector<fs::path> cases;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.path().extension() == ".toml") cases.push_back(e.path());
  std::sort(cases.begin(), cases.end());

  const auto t0 = std::chrono::steady_clock::now();
  std::map<int, std::size_t> by_code;
  std::vector<Variant> originals;
  for (const auto& file : cases)
    originals.push_back({file, fs::relative(file, root).string() + ": unmutated"});
  const auto checked = check_all(originals, true);
  report_failures(originals, checked, by_code);
  std::vector<bool> large(cases.size());
  std::size_t n_large = 0;
  for (std::size_t c = 0; c < cases.size(); ++c)
    n_large += large[c] = reported_nodes(checked[c].log) > kLargeModelNodes;

  const std::vector<Variant> variants = make_variants(root, cases, large);
  ASSERT_GE(variants.size(), 2000u) << "from " << cases.size() << " case files";
  report_failures(variants, check_all(variants, false), by_code);
  const std::vector<Variant> process = process_variants(root);
  const auto refused = check_all(process, true);
  for (std::size_t k = 0; k < process.size(); ++k)
    EXPECT_EQ(refused[k].code, 2) << process[k].what << ": " << refused[k].log.substr(0, 400);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::size_t n_checked = cases.size() + variants.size();
  std::printf(
      "fuzz: %zu case files (%zu of paper size) and %zu variants in %.0f s: %zu exit 0, %zu exit "
      "2, %zu other\n",
      cases.size(), n_large, variants.size(), wall, by_code[0], by_code[2],
      n_checked - by_code[0] - by_code[2]);
}

}  // namespace
}  // namespace ncfsim::test
