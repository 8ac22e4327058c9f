// SPDX-License-Identifier: BSD-3-Clause
// Writing output files so that a reader never sees a half-written file: the
// content goes to "<path>.tmp.<pid>" and is renamed over <path> when complete.
// The first write into a folder removes the temporaries there of processes
// that have ended (killed during a write).
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace radargauss {

// Calls write(stream) on a temporary file next to `path`, checks the stream,
// then renames the file to `path`. On any failure (including an exception
// from `write`) the temporary file is removed and DataError (or the
// exception) propagates; `path` is untouched.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write,
                         bool binary = false);

}  // namespace radargauss
