// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <sys/stat.h>
#include <sys/xattr.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <utility>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

// The temporaries' mark: "<name>.radargauss-tmp.<pid>", a name no other
// program's temporaries have, so that only ours are ever removed.
const std::string kMark = ".radargauss-tmp.";

std::string TemporaryOf(const std::string& path) { return path + kMark + std::to_string(::getpid()); }

// The mark the bag writer's temporaries had before they took kMark; such
// files of ended processes are removed as well.
const std::string kOldBagMark = ".radargauss-partial.";

// Whether `name` is a temporary of a process that has ended.
bool IsStaleTemporary(const std::string& name) {
  std::size_t mark = name.rfind(kMark), mark_size = kMark.size();
  if (mark == std::string::npos) mark = name.rfind(kOldBagMark), mark_size = kOldBagMark.size();
  if (mark == std::string::npos || mark + mark_size == name.size()) return false;
  const std::string digits = name.substr(mark + mark_size);
  if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) return false;
  const pid_t pid = pid_t(std::stol(digits));
  return pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH;
}

// Removes the temporary files and folders of `directory` whose process has
// ended (killed during a write), once per directory and process.
void RemoveStaleTemporaries(const fs::path& directory) {
  static std::mutex mutex;
  static std::set<fs::path> cleaned;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!cleaned.insert(directory).second) return;
  std::error_code error;
  for (fs::directory_iterator it(directory.empty() ? fs::path(".") : directory, error), end; !error && it != end;
       it.increment(error)) {
    if (IsStaleTemporary(it->path().filename().string())) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);  // a file, or a staged folder
    }
  }
}

// The files and folders of `old_dir` that `new_dir` lacks, hard-linked there
// (copied where links cannot be made): what a run did not write. A folder
// the run wrote replaces the old one whole.
void CarryOver(const fs::path& old_dir, const fs::path& new_dir, const std::vector<std::string>& superseded) {
  for (const fs::directory_entry& entry : fs::directory_iterator(old_dir)) {
    const fs::path there = new_dir / entry.path().filename();
    std::error_code error;
    if (fs::exists(fs::symlink_status(there, error)) || IsStaleTemporary(there.filename().string())) continue;
    if (std::find(superseded.begin(), superseded.end(), there.filename().string()) != superseded.end()) continue;
    if (entry.is_symlink(error)) {
      fs::copy_symlink(entry.path(), there, error);
    } else {
      fs::copy(entry.path(), there, fs::copy_options::recursive | fs::copy_options::create_hard_links, error);
      if (error) fs::copy(entry.path(), there, fs::copy_options::recursive, error);
    }
    if (error) throw FileError(entry.path().string(), "cannot keep it in the new results: " + error.message());
  }
}

// The old folder's mode (sticky, setgid and all), owner where permitted, and
// ACLs given to the staged folder that takes its place.
void KeepAttributes(const std::string& old_dir, const std::string& new_dir) {
  struct stat old_status {};
  if (::stat(old_dir.c_str(), &old_status) != 0) return;
  if (::chown(new_dir.c_str(), old_status.st_uid, old_status.st_gid) != 0) {
    [[maybe_unused]] const int ignored = ::chown(new_dir.c_str(), ::geteuid(), old_status.st_gid);  // the group alone
  }
  if (::chmod(new_dir.c_str(), old_status.st_mode & 07777) != 0) {
    throw FileError(old_dir, std::string("cannot give the new results the folder's mode: ") + std::strerror(errno));
  }
  for (const char* acl : {"system.posix_acl_access", "system.posix_acl_default"}) {
    std::vector<char> value(4096);
    const ssize_t size = ::getxattr(old_dir.c_str(), acl, value.data(), value.size());
    if (size > 0) ::setxattr(new_dir.c_str(), acl, value.data(), std::size_t(size), 0);
  }
}

// The folder a path names, absolute and without a trailing separator.
fs::path FolderPath(const std::string& target) {
  if (target.empty()) throw DataError("an output folder needs a name");
  std::error_code error;
  fs::path path = fs::weakly_canonical(fs::absolute(target), error);
  if (error) path = fs::absolute(target).lexically_normal();
  if (!path.has_filename()) path = path.parent_path();
  return path;
}

// Creates and removes `probe` (a temporary name beside an output): whether
// the output's folder takes a new file, tried rather than inferred from its
// mode (/proc, a read-only mount, a full inode table).
void TryCreating(const std::string& probe, const std::string& output) {
  const int fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return;  // this process is writing it now
    throw FileError(output, std::string("cannot be written: ") + std::strerror(errno));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

// Whether `path` (a file, or a folder and everything in it) holds a file this run has read.
bool HoldsProtectedInput(const fs::path& path) {
  std::error_code error;
  if (!fs::is_directory(fs::symlink_status(path, error))) return IsProtectedInput(path.string());
  for (fs::recursive_directory_iterator it(path, error), end; !error && it != end; it.increment(error)) {
    if (IsProtectedInput(it->path().string())) return true;
  }
  return false;
}

// CheckOutputFile's checks but the trial: for a writer that creates the
// file's temporary next, which is the trial.
void CheckOutputTarget(const std::string& path) {
  if (path.empty()) throw DataError("an output file needs a name");
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw FileError(path, fs::is_directory(status) ? "is a folder, not a file to write"
                                                   : "is not a regular file (a device or FIFO?); refused as an output");
  }
  if (IsProtectedInput(path)) throw FileError(path, "is read by this run; an output never replaces an input");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, error)) throw FileError(path, "its folder does not exist");
}

}  // namespace

void CheckOutputFile(const std::string& path) {
  CheckOutputTarget(path);
  TryCreating(TemporaryOf(path), path);
}

void CheckOutputFolder(const std::string& path) {
  const fs::path target = FolderPath(path);
  std::error_code error;
  if (fs::exists(target, error) && !fs::is_directory(target, error)) {
    throw FileError(path, "exists and is not a folder; refused as an output folder");
  }
  fs::path existing = target;
  while (!fs::exists(existing, error) && existing.has_parent_path() && existing != existing.parent_path()) {
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, error)) throw FileError(path, existing.string() + " is not a folder");
  TryCreating((existing / ("probe" + kMark + std::to_string(::getpid()))).string(), path);
}

std::string TemporaryFileFor(const std::string& path) {
  CheckOutputTarget(path);
  RemoveStaleTemporaries(fs::path(path).parent_path());
  return TemporaryOf(path);
}

StagedFolder::StagedFolder(const std::string& target, std::vector<std::string> superseded)
    : superseded_(std::move(superseded)) {
  const fs::path path = FolderPath(target);
  std::error_code error;
  if (fs::exists(path, error) && !fs::is_directory(path, error)) {
    throw FileError(target, "exists and is not a folder; refused as an output folder");
  }
  // Replacing a folder replaces its inode: not the root, not a shared folder.
  if (path == path.root_path()) throw FileError(target, "is the root folder; refused as an output folder");
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0 && (status.st_mode & S_ISVTX)) {
    throw FileError(target, "is a shared folder (sticky bit, as /tmp); name a folder of its own inside it");
  }
  fs::create_directories(path.parent_path(), error);
  if (error) throw FileError(target, "cannot create the output folder: " + error.message());
  RemoveStaleTemporaries(path.parent_path());
  target_ = path.string();
  staging_ = TemporaryOf(target_);
  fs::remove_all(staging_, error);
  if (!fs::create_directory(staging_, error)) {
    throw FileError(target, "cannot create the output folder: " + error.message());
  }
}

StagedFolder::~StagedFolder() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagedFolder::Commit() {
  std::error_code error;
  if (!fs::exists(target_, error)) {
    if (std::rename(staging_.c_str(), target_.c_str()) != 0) {
      throw FileError(target_, std::string("cannot move the results into place: ") + std::strerror(errno));
    }
    committed_ = true;
    return;
  }
  // What the new results replace (a name both hold) or drop (superseded) may not be a file this run read.
  for (const fs::directory_entry& entry : fs::directory_iterator(target_)) {
    const std::string name = entry.path().filename().string();
    const bool replaced = fs::exists(fs::symlink_status(fs::path(staging_) / name, error)) ||
                          std::find(superseded_.begin(), superseded_.end(), name) != superseded_.end();
    if (replaced && HoldsProtectedInput(entry.path())) {
      throw FileError(entry.path().string(), "is read by this run; its results never replace an input");
    }
  }
  CarryOver(target_, staging_, superseded_);
  KeepAttributes(target_, staging_);
  // One exchange: the target is the old folder or the new one, never a mix.
  // A file system without exchanges gets two renames (the old folder set
  // aside under the staging name's pattern, removed as stale if killed).
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0) {
    const std::string aside = staging_ + "-old";
    if ((errno != EINVAL && errno != ENOSYS) || std::rename(target_.c_str(), aside.c_str()) != 0 ||
        std::rename(staging_.c_str(), target_.c_str()) != 0) {
      throw FileError(target_, std::string("cannot move the results into place: ") + std::strerror(errno));
    }
    staging_ = aside;
  }
  committed_ = true;
  fs::remove_all(staging_, error);  // the old content
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write, bool binary) {
  const std::string temporary = TemporaryFileFor(path);
  try {
    {
      std::ofstream out(temporary, binary ? std::ios::out | std::ios::binary : std::ios::out);
      if (!out) throw FileError(path, "cannot open for writing");
      write(out);
      out.flush();
      if (!out) throw FileError(path, "write failed");
    }
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
      throw FileError(path, "cannot rename temporary file into place");
    }
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
}

}  // namespace radargauss
