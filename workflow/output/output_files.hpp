#pragma once
// The files of a run's output folder that the run writes and figures, report and calibration read
// back: log (console + log.txt), atomic replacement (summary.json, figures.json, report.html),
// history.csv and other numeric CSV. Shared by workflow/run, figures, report and calibrate, and
// includes none of them (dependencies point one way: run -> figures/report -> output).
#include <spdlog/logger.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "workflow/output/folder_lock.hpp"

namespace ncfsim::workflow {

enum class Verbosity { Quiet, Normal, Verbose };

/// Console + log.txt logger; the same lines go to both (the console honours the verbosity).
/// `append`: log.txt and warnings.txt are continued (a resumed run), not truncated.
std::shared_ptr<spdlog::logger> make_run_logger(const std::filesystem::path& out_dir, Verbosity v,
                                                bool append = false);

/// The whole file as bytes; empty when it cannot be read.
std::string read_file(const std::filesystem::path& path);
/// A JSON file (summary.json, a manifest); null when it is missing or cannot be parsed.
nlohmann::json read_json_file(const std::filesystem::path& path);
/// Wall time as "MM:SS", "H:MM:SS" past an hour, "--:--" when not a time.
std::string hms(double seconds);

/// Writes text to `path` so that a reader sees either the old or the new complete file
/// (fem/io/atomic_file.hpp).
void write_file_atomically(const std::filesystem::path& path, const std::string& text);

/// An output folder that ncfsim owns only in part: `.ncfsim_manifest.json` lists what ncfsim
/// wrote there, so a rerun removes exactly that and never a file of the user's. Life cycle:
/// claim() before the first file is written, finish() once the run has written its last.
/// A run that dies in between leaves a manifest marked incomplete with the files that were there
/// before it; the next claim() removes everything else. One process at a time: claim() and
/// resume() take the folder's lock (FolderLock) before they touch anything, and the object holds
/// it until it goes, so a second run into the folder is refused at once (exit 2).
class OutputFolder {
 public:
  /// Creates dir or clears what an earlier run of ncfsim wrote there. A folder in use by another
  /// process, or a non-empty folder without a manifest, is refused (InputError naming the folder
  /// and the holder, or a file in it) unless `overwrite` for the latter; entries named in `keep`
  /// (a workflow's stage folders) are neither removed nor counted. `what` names the writer in the
  /// lock file ("run", "workflow", "transfer", ...).
  static OutputFolder claim(const std::filesystem::path& dir, bool overwrite,
                            const std::vector<std::string>& keep = {},
                            const std::string& what = "run");
  /// Takes over the folder of an interrupted run to continue it (`--resume`): its files stay,
  /// the files that were there before that run stay the user's; the manifest is marked
  /// incomplete until finish(). InputError when the folder holds no manifest of ncfsim, or when
  /// another process holds it.
  static OutputFolder resume(const std::filesystem::path& dir);
  /// Rewrites the manifest with every file and folder written since claim().
  void finish() const;
  /// Adds files written into a finished run's folder later (`ncfsim render`, `report`,
  /// `export`) to its manifest, so a rerun clears them too; no manifest: nothing to do.
  static void record(const std::filesystem::path& dir,
                     const std::vector<std::filesystem::path>& files);
  const std::filesystem::path& dir() const { return dir_; }
  /// Non-empty when claim() found the summary of a run that died without a status (it said
  /// "running" and no process held the folder): what the new run should warn about.
  const std::string& note() const { return note_; }

 private:
  std::filesystem::path dir_;
  std::vector<std::string> before_files_, before_dirs_, keep_;
  std::filesystem::file_time_type start_;
  std::unique_ptr<FolderLock> lock_;
  std::string note_;
};

/// history.csv: a header with named columns (units in the names), then one row per output time.
/// Each row is flushed, so an interrupted run leaves only complete rows; a row the file system
/// refuses throws std::runtime_error naming the file and the reason.
class HistoryWriter {
 public:
  /// `append`: continues an existing file (a resumed run) without writing the header.
  HistoryWriter(const std::filesystem::path& file, std::vector<std::string> columns,
                bool append = false);
  void write_row(const std::vector<double>& values);
  const std::vector<std::string>& columns() const { return columns_; }

 private:
  void write_line(const std::string& line);
  std::ofstream out_;
  std::vector<std::string> columns_;
  std::filesystem::path file_;
};

/// Reads a CSV written by HistoryWriter (or any numeric CSV with a header row).
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  /// Column values; throws std::out_of_range naming the column when absent.
  std::vector<double> column(const std::string& name) const;
};
CsvTable read_csv(const std::filesystem::path& file);

}  // namespace ncfsim::workflow
