// Whole-file writes that never leave a partial file behind.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <string_view>

namespace tessera::io {

/// Write `path` by streaming into `path.tmp-XXXX` in the same directory and
/// renaming it over `path` once complete. On any failure (directory missing,
/// not writable, disk full, exception from `fill`) the temporary is removed,
/// `path` is untouched, and tessera::InputError("cannot write PATH: reason") is thrown.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& fill);
void write_file_atomic(const std::string& path, std::string_view bytes);

/// Fail early (before a long computation) if `path` cannot be created:
/// its directory must exist and be writable. Throws InputError.
void check_writable(const std::string& path);

}  // namespace tessera::io
