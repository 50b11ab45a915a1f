// --walls FILE: many walls at once (a polyhedron's faces, a hull saved by
// tessera.hull_walls), where repeating --wall on the command line would not
// do (the hull of 100k points on a sphere has 200k walls).
#pragma once

#include <string>
#include <vector>

namespace tessera::cli {

/// The walls in `path`, one row each as given (NX NY D or NX NY NZ D: the
/// caller checks the count against the points' dimension). A `.npy` holds a
/// float or integer array of shape (k, 3) or (k, 4), or one wall of shape
/// (3,) or (4,); any other file is text, one wall a line, its numbers
/// separated by commas, semicolons or whitespace, blank lines and lines
/// starting with '#' skipped. Throws InputError naming the file (and the
/// line) for anything else: no walls, a row of another length, a word that
/// is not a number. Values are not checked here (make_options and the
/// library refuse NaN, zero normals).
std::vector<std::vector<double>> read_walls_file(const std::string& path);

}  // namespace tessera::cli
