#pragma once
// The folder of a run (capsule_run.hpp): which of its files are the run's, what a new run, an
// overwrite and a resume may do to them, and the checks a resume makes of the snapshots.
//
// A run's files are its fixed outputs (timeseries.csv or the recorder's files, checkpoint.json,
// summary.json, timing.json, shapes.pvd, D_theta.png), snapshot_NNNNN.vtp, the solver's side
// files, and the temporaries the run itself can have left for one of them: AtomicFile's
// "<output>.tmp" and mkstemp's six letters or digits (core/atomic_file.hpp), or a side file's
// "<side file>.tmp" (parallel/distributed_checkpoint.hpp). Nothing that merely looks like one is
// the run's: "timeseries.csv.tmp-backup" or "summary.json.tmp" are a user's files, which
// --resume and --overwrite never remove.
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/core/folder_lock.hpp"

namespace bendlab {

struct CapsuleCheckpoint;

class RunFolder {
 public:
  using NamePredicate = std::function<bool(const std::string&)>;
  /// `recorder_output` and `side_file` name the recorder's and the solver's files.
  RunFolder(std::filesystem::path folder, NamePredicate recorder_output, NamePredicate side_file);

  const std::filesystem::path& path() const { return folder_; }
  /// An output of the run (not a temporary).
  bool is_output(const std::string& name) const;
  /// An output or a temporary the run can have left for one (the files --overwrite removes).
  bool is_run_file(const std::string& name) const;

  /// Creates the folder for a new run (its parent must exist) and locks it (core/folder_lock.hpp):
  /// a second run into it is refused at once. A resume only locks an existing folder.
  void lock(bool resume);
  /// A new run: refuses a folder holding another run's files unless `overwrite`, which removes
  /// them (files of other names are never touched).
  void clear_for_new_run(bool overwrite) const;
  /// Removes the temporaries an interrupted write left.
  void remove_temporaries() const;
  /// The checkpoint's snapshot list: snapshot_00000.vtp, snapshot_00001.vtp, ... (every one the
  /// run wrote, in order), the last at the checkpoint's time, and no later snapshot in the folder
  /// (it belongs to a later history than the checkpoint's and would be overwritten). The listed
  /// files need not be present: a study's run folder moves between machines without them.
  void check_snapshots(const CapsuleCheckpoint& c, const std::string& source) const;
  /// Writes folder/name whole (AtomicFile), as indented JSON.
  void write_json(const std::string& name, const nlohmann::json& j) const;

 private:
  std::vector<std::string> run_files(bool temporaries_only) const;
  void remove(const std::vector<std::string>& names) const;

  std::filesystem::path folder_;
  NamePredicate recorder_output_, side_file_;
  std::optional<FolderLock> lock_;
};

}  // namespace bendlab
