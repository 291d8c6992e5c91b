#include "workflow/output/output_files.hpp"

#include <fmt/format.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "fem/errors.hpp"
#include "fem/io/atomic_file.hpp"

namespace ncfsim::workflow {

std::shared_ptr<spdlog::logger> make_run_logger(const std::filesystem::path& out_dir, Verbosity v,
                                                bool append) {
  auto console = std::make_shared<spdlog::sinks::stdout_color_sink_mt>();
  console->set_pattern("%v");
  console->set_level(v == Verbosity::Quiet     ? spdlog::level::warn
                     : v == Verbosity::Verbose ? spdlog::level::debug
                                               : spdlog::level::info);
  std::vector<spdlog::sink_ptr> sinks{console};
  if (!out_dir.empty()) {
    auto file = std::make_shared<spdlog::sinks::basic_file_sink_mt>((out_dir / "log.txt").string(),
                                                                    !append);
    file->set_pattern("[%Y-%m-%d %H:%M:%S] %v");
    file->set_level(v == Verbosity::Verbose ? spdlog::level::debug : spdlog::level::info);
    sinks.push_back(file);
    // The warnings alone, for the workflow's report (one list over every stage).
    auto warnings = std::make_shared<spdlog::sinks::basic_file_sink_mt>(
        (out_dir / "warnings.txt").string(), !append);
    warnings->set_pattern("%v");
    warnings->set_level(spdlog::level::warn);
    sinks.push_back(warnings);
  }
  auto log = std::make_shared<spdlog::logger>("ncfsim", sinks.begin(), sinks.end());
  log->set_level(spdlog::level::debug);
  log->flush_on(spdlog::level::info);
  return log;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json read_json_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  const auto j = nlohmann::json::parse(in, nullptr, false);
  return j.is_discarded() ? nlohmann::json(nullptr) : j;
}

std::string hms(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const auto s = static_cast<long>(seconds + 0.5);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{:02}:{:02}", s / 60, s % 60);
}

void write_file_atomically(const std::filesystem::path& path, const std::string& text) {
  fem::io::atomic_write_text(path, text);
}

HistoryWriter::HistoryWriter(const std::filesystem::path& file, std::vector<std::string> columns,
                             bool append)
    : out_(file, append ? std::ios::app : std::ios::out),
      columns_(std::move(columns)),
      file_(file) {
  if (!out_)
    throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
  if (append) return;
  std::string header;
  for (std::size_t i = 0; i < columns_.size(); ++i) header += (i ? "," : "") + columns_[i];
  write_line(header + '\n');
}

// A row that does not reach the file (a full disk, a file-size limit) ends the run with the file
// and the system's reason, rather than leaving a history that stops short without a word.
void HistoryWriter::write_line(const std::string& line) {
  errno = 0;
  out_ << line;
  out_.flush();
  if (!out_)
    throw std::runtime_error("cannot write " + file_.string() + ": " +
                             (errno ? std::strerror(errno) : "write failed"));
}

void HistoryWriter::write_row(const std::vector<double>& values) {
  std::string line;
  line.reserve(values.size() * 16);
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line += ',';
    line += fmt::format("{:.9g}", values[i]);
  }
  line += '\n';
  write_line(line);
}

std::vector<double> CsvTable::column(const std::string& name) const {
  for (std::size_t c = 0; c < columns.size(); ++c)
    if (columns[c] == name) {
      std::vector<double> v;
      v.reserve(rows.size());
      for (const auto& r : rows) v.push_back(c < r.size() ? r[c] : 0.0);
      return v;
    }
  throw std::out_of_range("no column '" + name + "'");
}

CsvTable read_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  CsvTable t;
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(file.string() + " is empty");
  // A file written on Windows (or by Python's csv module) ends its lines with CR LF.
  const auto chomp = [](std::string& l) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
  };
  chomp(line);
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) t.columns.push_back(c);
  }
  while (std::getline(in, line)) {
    chomp(line);
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) row.push_back(std::strtod(c.c_str(), nullptr));
    if (row.size() == t.columns.size()) t.rows.push_back(std::move(row));  // skip a torn last line
  }
  return t;
}

namespace {

constexpr const char* kManifest = ".ncfsim_manifest.json";

// Files and folders under dir (relative, generic form), skipping the manifest and the entries
// named in keep (at the top level).
void list_tree(const std::filesystem::path& dir, const std::vector<std::string>& keep,
               std::vector<std::string>& files, std::vector<std::string>& dirs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const std::string rel = fs::relative(it->path(), dir).generic_string();
    if (it.depth() == 0 && (rel == kManifest || rel == kFolderLockFile ||
                            std::find(keep.begin(), keep.end(), rel) != keep.end())) {
      if (it->is_directory()) it.disable_recursion_pending();
      continue;
    }
    (it->is_directory() ? dirs : files).push_back(rel);
  }
  std::sort(files.begin(), files.end());
  std::sort(dirs.begin(), dirs.end());
}

bool listed(const std::vector<std::string>& sorted, const std::string& s) {
  return std::binary_search(sorted.begin(), sorted.end(), s);
}

}  // namespace

OutputFolder OutputFolder::claim(const std::filesystem::path& dir, bool overwrite,
                                 const std::vector<std::string>& keep, const std::string& what) {
  namespace fs = std::filesystem;
  OutputFolder o;
  o.dir_ = dir;
  o.keep_ = keep;
  if (fs::exists(dir) && !fs::is_directory(dir))
    throw InputError(dir.string(), "-o", "is a file, not a folder");
  fs::create_directories(dir);
  o.lock_ = FolderLock::acquire(dir, what);
  {  // held now: a summary still "running" belongs to a process that is gone
    const nlohmann::json last = read_json_file(dir / "summary.json");
    if (last.is_object() && last.value("status", "") == "running")
      o.note_ = "the last run in this folder ended without a status (summary.json said running" +
                (last.contains("cycles") ? ", at cycle " + last["cycles"].dump() : std::string()) +
                "): it was killed or lost an MPI rank; its files are replaced";
  }
  const fs::path manifest = dir / kManifest;
  if (fs::exists(manifest)) {
    const nlohmann::json m = read_json_file(manifest);
    if (!m.is_object())
      throw InputError(manifest.string(), "", "cannot be read: remove it, or give another folder");
    std::vector<std::string> files, dirs;
    list_tree(dir, keep, files, dirs);
    std::vector<std::string> ours, keep_files = m.value("before_files", std::vector<std::string>{}),
                                   keep_dirs = m.value("before_dirs", std::vector<std::string>{});
    std::sort(keep_files.begin(), keep_files.end());
    std::sort(keep_dirs.begin(), keep_dirs.end());
    if (m.value("complete", false)) {  // exactly what it lists
      for (const auto& f : m.value("files", std::vector<std::string>{})) fs::remove(dir / f);
      ours = m.value("dirs", std::vector<std::string>{});
    } else {  // a run that died: everything that was not there before it
      for (const auto& f : files)
        if (!listed(keep_files, f)) fs::remove(dir / f);
      for (const auto& d : dirs)
        if (!listed(keep_dirs, d)) ours.push_back(d);
    }
    std::sort(ours.rbegin(), ours.rend());  // deepest first; a folder left non-empty stays
    for (const auto& d : ours) {
      std::error_code ec;
      fs::remove(dir / d, ec);
    }
    fs::remove(manifest);
  } else if (!overwrite) {
    std::vector<std::string> files, dirs;
    list_tree(dir, keep, files, dirs);
    if (!files.empty() || !dirs.empty())
      throw InputError(dir.string(), "-o",
                       "holds files ncfsim did not write (e.g. " +
                           (files.empty() ? dirs.front() : files.front()) +
                           "): give an empty or new output folder, or --overwrite to write beside "
                           "them (files of the same names are replaced, nothing else is touched)");
  }
  list_tree(dir, keep, o.before_files_, o.before_dirs_);
  o.start_ = fs::file_time_type::clock::now();
  const nlohmann::json m = {
      {"complete", false}, {"before_files", o.before_files_}, {"before_dirs", o.before_dirs_}};
  write_file_atomically(manifest, m.dump(1) + "\n");
  return o;
}

OutputFolder OutputFolder::resume(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  const fs::path manifest = dir / kManifest;
  const auto not_ours = [&] {
    return InputError(
        dir.string(), "--resume",
        "is not an output folder of ncfsim (no readable " + std::string(kManifest) + ")");
  };
  if (!fs::is_regular_file(manifest)) throw not_ours();
  OutputFolder o;
  o.dir_ = dir;
  o.lock_ = FolderLock::acquire(dir, "run (resumed)");  // before the manifest is read
  const nlohmann::json m = read_json_file(manifest);
  if (!m.is_object()) throw not_ours();
  o.before_files_ = m.value("before_files", std::vector<std::string>{});
  o.before_dirs_ = m.value("before_dirs", std::vector<std::string>{});
  std::sort(o.before_files_.begin(), o.before_files_.end());
  std::sort(o.before_dirs_.begin(), o.before_dirs_.end());
  o.start_ = fs::file_time_type::clock::now();
  std::error_code ec;
  fs::remove(dir / "checkpoint.h5.tmp", ec);  // left by a run killed while it wrote one
  const nlohmann::json incomplete = {
      {"complete", false}, {"before_files", o.before_files_}, {"before_dirs", o.before_dirs_}};
  write_file_atomically(manifest, incomplete.dump(1) + "\n");
  return o;
}

void OutputFolder::finish() const {
  namespace fs = std::filesystem;
  std::vector<std::string> files, dirs, ours_f, ours_d;
  list_tree(dir_, keep_, files, dirs);
  for (const auto& f : files) {
    std::error_code ec;
    const auto t = fs::last_write_time(dir_ / f, ec);
    if (!listed(before_files_, f) || (!ec && t >= start_)) ours_f.push_back(f);
  }
  for (const auto& d : dirs)
    if (!listed(before_dirs_, d)) ours_d.push_back(d);
  std::vector<std::string> still_before;
  for (const auto& f : before_files_)
    if (!listed(ours_f, f)) still_before.push_back(f);
  const nlohmann::json m = {{"complete", true},
                            {"files", ours_f},
                            {"dirs", ours_d},
                            {"before_files", still_before},
                            {"before_dirs", before_dirs_}};
  write_file_atomically(dir_ / kManifest, m.dump(1) + "\n");
}

void OutputFolder::record(const std::filesystem::path& dir,
                          const std::vector<std::filesystem::path>& files) {
  namespace fs = std::filesystem;
  const fs::path manifest = dir / kManifest;
  nlohmann::json m = read_json_file(manifest);
  // No manifest: nothing to add to; an unreadable one: claim() reports it on the next run.
  if (!m.is_object() || !m.value("complete", false)) return;
  auto ours = m.value("files", std::vector<std::string>{});
  auto before = m.value("before_files", std::vector<std::string>{});
  for (const auto& f : files) {
    const std::string rel = fs::relative(f, dir).generic_string();
    if (rel.empty() || rel.rfind("..", 0) == 0) continue;
    if (std::find(ours.begin(), ours.end(), rel) == ours.end()) ours.push_back(rel);
    before.erase(std::remove(before.begin(), before.end(), rel), before.end());
  }
  std::sort(ours.begin(), ours.end());
  m["files"] = ours;
  m["before_files"] = before;
  write_file_atomically(manifest, m.dump(1) + "\n");
}

}  // namespace ncfsim::workflow
