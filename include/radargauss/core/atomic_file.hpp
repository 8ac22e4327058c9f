// SPDX-License-Identifier: BSD-3-Clause
// Writing outputs so that a reader never sees a half-written file or folder:
// the content goes to "<path>.radargauss-tmp.<pid>" and is renamed over <path> when
// complete. The first write into a folder removes the temporaries there of
// processes that have ended (killed during a write).
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace radargauss {

// Calls write(stream) on a temporary file next to `path`, checks the stream,
// then renames the file to `path`. On any failure (including an exception
// from `write`) the temporary file is removed and DataError (or the
// exception) propagates; `path` is untouched.
// `path` must name a regular file or nothing: a device node, a FIFO or a
// folder there is refused (DataError), never replaced.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write, bool binary = false);

// Throws DataError naming `path` unless a file could be written there: its
// folder exists, a file can be created in it (tried), `path` names a
// regular file or nothing, and not a file this run has read
// (read_file.hpp, ProtectInputs). Lets a command that writes two files
// check both before writing either.
void CheckOutputFile(const std::string& path);

// Throws DataError naming `path` unless a results folder could be made
// there: the nearest folder on its path that exists takes a new entry
// (tried), and `path` names a folder or nothing.
void CheckOutputFolder(const std::string& path);

// The temporary name a writer that cannot go through WriteFileAtomically (a
// sqlite3 database, a file written over a whole run) writes `path` under,
// to rename it over `path` when complete: "<path>.radargauss-tmp.<pid>",
// after CheckOutputFile's checks (but its trial: creating the temporary is
// one); the temporaries beside it of processes that have ended (killed
// during a write) are removed first.
std::string TemporaryFileFor(const std::string& path);

// A results folder written whole: a command writes into path(), a staging
// folder beside the target, and Commit() puts it in place with one rename
// (an exchange when the target exists), so the target holds either its old
// content or the complete new one. The files and folders of an existing
// target that this run did not write are kept (hard links); a folder it
// wrote replaces the old one whole, and the `superseded` names (the
// command's outputs: an old evaluation.json describes an old trajectory) are
// not kept whether or not this run wrote them. The new folder takes the old
// one's mode, owner (where permitted) and ACLs. Without Commit() the staging
// folder is removed and the target is left as it was.
class StagedFolder {
 public:
  // Throws DataError naming `target` when it exists and is not a folder, is
  // the root or a shared folder (sticky bit, as /tmp), or the staging folder
  // cannot be made.
  explicit StagedFolder(const std::string& target, std::vector<std::string> superseded = {});
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  const std::string& path() const { return staging_; }
  void Commit();

 private:
  std::string target_;
  std::string staging_;
  std::vector<std::string> superseded_;
  bool committed_ = false;
};

}  // namespace radargauss
