// "-" as a point file: standard input, for pipelines such as
// `rbox 1000 D3 | tessera voronoi - -o cells.vtu`.
#pragma once

#include <string>

namespace tessera::cli {

/// `arg` itself, or for "-" standard input spooled into a temporary file
/// (io::TemporaryFile, removed at exit or on a fatal signal) whose extension
/// is the format its first bytes show: .npy, .ply, .pcd, .vtp/.vtu/.vti, .dump,
/// .nrrd, .mha, else .txt (csv, xyz, Qhull's format). Standard input is read
/// once; a second "-" (threshold's scalars read the points' file again) is
/// the same file. Throws InputError where standard input is a terminal.
std::string input_path(const std::string& arg);

/// How to name `path` in a summary: "stdin" for "-" and for the spool.
std::string shown_path(const std::string& path);

/// `message` with the spool's path, wherever it occurs, named "stdin".
std::string name_stdin(std::string message);

}  // namespace tessera::cli
