#include "workflow/output/output_files.hpp"

#include <fmt/format.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "fem/io/atomic_file.hpp"

namespace ncfsim::workflow {

std::shared_ptr<spdlog::logger> make_run_logger(const std::filesystem::path& out_dir, Verbosity v) {
  auto console = std::make_shared<spdlog::sinks::stdout_color_sink_mt>();
  console->set_pattern("%v");
  console->set_level(v == Verbosity::Quiet     ? spdlog::level::warn
                     : v == Verbosity::Verbose ? spdlog::level::debug
                                               : spdlog::level::info);
  std::vector<spdlog::sink_ptr> sinks{console};
  if (!out_dir.empty()) {
    auto file =
        std::make_shared<spdlog::sinks::basic_file_sink_mt>((out_dir / "log.txt").string(), true);
    file->set_pattern("[%Y-%m-%d %H:%M:%S] %v");
    file->set_level(v == Verbosity::Verbose ? spdlog::level::debug : spdlog::level::info);
    sinks.push_back(file);
    // The warnings alone, for the workflow's report (one list over every stage).
    auto warnings = std::make_shared<spdlog::sinks::basic_file_sink_mt>(
        (out_dir / "warnings.txt").string(), true);
    warnings->set_pattern("%v");
    warnings->set_level(spdlog::level::warn);
    sinks.push_back(warnings);
  }
  auto log = std::make_shared<spdlog::logger>("ncfsim", sinks.begin(), sinks.end());
  log->set_level(spdlog::level::debug);
  log->flush_on(spdlog::level::info);
  return log;
}

void write_file_atomically(const std::filesystem::path& path, const std::string& text) {
  fem::io::atomic_write_text(path, text);
}

HistoryWriter::HistoryWriter(const std::filesystem::path& file, std::vector<std::string> columns)
    : out_(file), columns_(std::move(columns)) {
  if (!out_) throw std::runtime_error("cannot write " + file.string());
  for (std::size_t i = 0; i < columns_.size(); ++i) out_ << (i ? "," : "") << columns_[i];
  out_ << '\n';
  out_.flush();
}

void HistoryWriter::write_row(const std::vector<double>& values) {
  std::string line;
  line.reserve(values.size() * 16);
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line += ',';
    line += fmt::format("{:.9g}", values[i]);
  }
  line += '\n';
  out_ << line;
  out_.flush();
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
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) t.columns.push_back(c);
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) row.push_back(std::strtod(c.c_str(), nullptr));
    if (row.size() == t.columns.size()) t.rows.push_back(std::move(row));  // skip a torn last line
  }
  return t;
}

}  // namespace ncfsim::workflow
