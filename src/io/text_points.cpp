// Text point files: .csv, .xyz, .txt.
//
// Rules (see points.hpp):
//  - fields are separated by ',' or ';' (picked from the first content line; blanks
//    around fields are trimmed) or else by runs of spaces/tabs;
//  - blank lines and lines starting with '#' are skipped; CRLF and a UTF-8 BOM are fine;
//  - the first content line is a header when one of its fields is not a number;
//  - a header naming columns x and y (any case, in any position) takes the
//    coordinates from them, and from z if named: 3D, else 2D;
//  - otherwise the columns (other than a labels column) give the coordinates:
//    2 -> 2D, 3 or more -> 3D (extras ignored); ReadOptions::dim forces either;
//  - every data line must have the columns needed; errors name the line (1-based).
// Qhull's input format (what `rbox` writes, `rbox 1000 D3 | qhull`) is read
// as well: a first line holding the dimension (then, optionally, a comment
// such as "rbox 1000 D3"), a second holding the number of points (qhull
// takes the two either way round: the smaller is the dimension), then the
// coordinates, whitespace-separated (qhull_points below). A plain point
// file cannot start so: its first line would be a point of one coordinate.
// The whole file is read into memory and parsed with std::from_chars.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "io_detail.hpp"
#include "text_fields.hpp"
#include "tessera/cells.hpp"

namespace tessera::io::detail {
namespace {

/// The layout read off a text file's first content line: delimiter (',', ';'
/// or whitespace), whether it is a header (some field is not a number), the
/// column names (quotes stripped; empty without a header) and the count.
struct TextLayout {
  char delim = ' ';
  bool header = false;
  std::vector<std::string> names;
  std::size_t ncols = 0;
};

TextLayout text_layout(std::string_view line) {
  TextLayout t;
  t.delim = line.find(',') != std::string_view::npos   ? ','
            : line.find(';') != std::string_view::npos ? ';'
                                                       : ' ';
  std::vector<std::string_view> first;
  Fields fs(line, t.delim);
  std::string_view f;
  while (fs.next(f)) first.push_back(f);
  for (std::string_view g : first) {
    double v;
    if (!g.empty() && !parse_double(g, v)) t.header = true;
  }
  if (t.header) {
    for (std::string_view g : first) {
      if (g.size() >= 2 && (g.front() == '"' || g.front() == '\'') && g.back() == g.front())
        g = g.substr(1, g.size() - 2);
      t.names.emplace_back(g);
    }
  }
  t.ncols = first.size();
  return t;
}

/// Index of the header column `name`, `what` naming its use in errors.
std::size_t find_column(const std::string& path, const TextLayout& t, const std::string& name,
                        const std::string& what) {
  if (!t.header) fail(path, what + " '" + name + "': the file has no header line naming its columns");
  auto it = std::find(t.names.begin(), t.names.end(), name);
  if (it == t.names.end()) fail(path, "no column '" + name + "' for " + what + " (columns: " + quoted_list(t.names) + ")");
  return static_cast<std::size_t>(it - t.names.begin());
}

/// A whole field as a non-negative integer.
bool parse_count(std::string_view f, std::size_t& out) {
  auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), out);
  return ec == std::errc() && p == f.data() + f.size();
}

/// Whether `line` is an integer alone or before a comment (a field that is
/// not a number: "3 rbox 1000 D3"); sets it. "3 10" is a 2D point.
bool count_line(std::string_view line, std::size_t& out) {
  Fields fs(line, ' ');
  std::string_view x, y;
  if (!fs.next(x) || !parse_count(x, out)) return false;
  double v;
  return !fs.next(y) || !parse_double(y, v);
}

/// Whether the file's first two content lines have the shape of Qhull's
/// input header; sets their integers.
bool qhull_header(std::string_view line1, std::string_view line2, std::size_t& a, std::size_t& b) {
  return count_line(line1, a) && count_line(line2, b);
}

/// Points in Qhull's input format, whose header qhull_header read: `ndim`
/// (at least 2) coordinates per point, `count` points, the numbers after
/// the header in any layout (one point per line, as rbox writes them, or
/// not). Labels can come only from a .npy file (the format names no columns).
PointCloud qhull_points(const std::string& path, Lines& lines, std::size_t ndim, std::size_t count,
                        const ReadOptions& options, const std::string& label_column) {
  if (!label_column.empty())
    fail(path, "labels '" + label_column +
                   "': Qhull's point format names no columns (give labels as a .npy file)");
  if (ndim > 3 && options.dim == 0)
    fail(path, "Qhull point format of dimension " + std::to_string(ndim) +
                   ": tessera computes 2D and 3D cells (--dim 2 or 3 keeps the first coordinates)");
  if (count > std::numeric_limits<std::size_t>::max() / ndim)
    fail(path, "Qhull point format: its header declares " + std::to_string(count) + " points, more than can be held");
  const std::size_t dim = options.dim != 0 ? static_cast<std::size_t>(options.dim) : ndim;
  if (dim > ndim) fail(path, "3D points asked but the file's points have " + std::to_string(ndim) + " coordinates");
  // The numbers are checked against the header's count before any array is
  // sized by it (a corrupt count must not allocate).
  PointCloud pc;
  pc.dim = static_cast<int>(dim);
  std::size_t seen = 0;
  std::string_view line, f;
  std::size_t line_no = 0;
  while (lines.next(line, line_no)) {
    Fields fs(line, ' ');
    while (fs.next(f)) {
      double v;
      if (!parse_double(f, v))
        fail(path, "line " + std::to_string(line_no) + ": cannot parse '" + std::string(f) + "' as a number");
      if (!std::isfinite(v) && !options.keep_non_finite)
        fail(path, "line " + std::to_string(line_no) + ": non-finite coordinate '" + std::string(f) + "' (" +
                       non_finite_hint(options) + ")");
      if (seen / ndim >= count)
        fail(path, "Qhull point format: more numbers than the " + std::to_string(count) + " points of dimension " +
                       std::to_string(ndim) + " its header declares (line " + std::to_string(line_no) + ")");
      if (seen % ndim < dim) pc.coords.push_back(v);
      ++seen;
    }
  }
  if (seen != count * ndim)
    fail(path, "Qhull point format: its header declares " + std::to_string(count) + " points of dimension " +
                   std::to_string(ndim) + " (" + std::to_string(count * ndim) + " numbers), the file holds " +
                   std::to_string(seen));
  pc.n = count;
  return pc;
}

}  // namespace

PointCloud read_text_points(const std::string& path, const ReadOptions& options,
                            const std::string& label_column) {
  // XYZ (chemistry's, and extended XYZ): a lone count, a comment, the atoms;
  // of a trajectory, options.frame alone is read.
  if (is_xyz_file(path)) return read_xyz_points(path, options, label_column);
  const std::string text = read_file_bytes(path);
  Lines lines(text);
  std::string_view line;
  std::size_t line_no = 0;
  if (!lines.next(line, line_no)) fail(path, "no points");
  {
    // Qhull's header, unless what follows is a column of single numbers (a
    // one-column file, whose error is the plain reader's).
    Lines after = lines;
    std::string_view second, third;
    std::size_t no = 0, a = 0, b = 0;
    if (after.next(second, no) && qhull_header(line, second, a, b) && std::min(a, b) >= 2) {
      Lines rest = after;
      std::size_t fields = 2;
      if (rest.next(third, no)) {
        Fields fs(third, ' ');
        std::string_view f;
        for (fields = 0; fields < 2 && fs.next(f);) ++fields;
      }
      if (fields >= 2) return qhull_points(path, after, std::min(a, b), std::max(a, b), options, label_column);
    }
  }

  // Layout from the first content line: delimiter, header, column count.
  const TextLayout layout = text_layout(line);
  const char delim = layout.delim;
  const bool header = layout.header;
  const std::size_t ncols = layout.ncols;

  // Which column holds labels, if any.
  std::size_t label_col = ncols;  // ncols = none
  if (!label_column.empty()) label_col = find_column(path, layout, label_column, "labels");

  // Coordinate columns: those a header names x, y (and z), or else the first
  // `dim` columns other than the labels column.
  const NamedAxes named =
      layout.header ? named_axes(path, layout.names, label_column, options.dim, "column") : NamedAxes{};
  int dim = options.dim;
  std::size_t coord_col[3] = {0, 0, 0};
  if (named.found) {
    // (A pandas frame saved with to_csv() leads with its unnamed index
    // column, and tables often lead with an id: the first columns would
    // make the index a coordinate.)
    dim = named.dim;
    for (int k = 0; k < dim; ++k) coord_col[k] = named.col[k];
  } else {
    const std::size_t avail = ncols - (label_col < ncols ? 1 : 0);
    if (dim == 0) {
      if (avail < 2)
        fail(path, "line " + std::to_string(line_no) + " has " + std::to_string(avail) +
                       " coordinate column(s); need 2 (x,y) or 3 (x,y,z)");
      dim = avail >= 3 ? 3 : 2;
    } else if (avail < static_cast<std::size_t>(dim)) {
      fail(path, std::to_string(dim) + "D points asked but line " + std::to_string(line_no) + " has " +
                     std::to_string(avail) + " coordinate column(s)");
    }
    for (std::size_t c = 0, k = 0; k < static_cast<std::size_t>(dim); ++c)
      if (c != label_col) coord_col[k++] = c;
  }
  // Field index -> slot: 0..dim-1 a coordinate, 3 the label, -1 ignored.
  std::size_t needed = (label_col < ncols ? label_col : 0) + 1;
  for (int k = 0; k < dim; ++k) needed = std::max(needed, coord_col[k] + 1);
  std::vector<int> slot(needed, -1);
  for (int k = 0; k < dim; ++k) slot[coord_col[k]] = k;
  if (label_col < ncols) slot[label_col] = 3;

  PointCloud pc;
  pc.dim = dim;
  // Rows <= lines: counting newlines is cheap next to parsing and avoids regrowth.
  const std::size_t max_rows = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  pc.coords.reserve(max_rows * static_cast<std::size_t>(dim));
  if (label_col < ncols) pc.labels.reserve(max_rows);

  bool have = !header;  // the first line is data unless it was the header
  if (!have) have = lines.next(line, line_no);
  for (; have; have = lines.next(line, line_no)) {
    Fields fs(line, delim);
    std::string_view f;
    double xyz[3] = {0, 0, 0};
    std::size_t c = 0;
    for (; c < needed && fs.next(f); ++c) {
      const int s = slot[c];
      if (s < 0) continue;
      if (s == 3) {
        std::int32_t lab;
        if (!parse_label(f, lab))
          fail(path, "line " + std::to_string(line_no) + ": label '" + std::string(f) + "' in column '" +
                         label_column + "' is not a 32-bit integer");
        pc.labels.push_back(lab);
        continue;
      }
      if (!parse_double(f, xyz[s])) {
        if (f.empty())
          fail(path, "line " + std::to_string(line_no) + ": empty field in column " + std::to_string(c + 1));
        fail(path, "line " + std::to_string(line_no) + ": cannot parse '" + std::string(f) +
                       "' as a number (column " + std::to_string(c + 1) + ")");
      }
      if (!std::isfinite(xyz[s]) && !options.keep_non_finite)
        fail(path, "line " + std::to_string(line_no) + ": non-finite coordinate '" + std::string(f) + "' (" +
                       non_finite_hint(options) + ")");
    }
    if (c < needed)
      fail(path, "line " + std::to_string(line_no) + " has " + std::to_string(c) +
                     " column(s), expected at least " + std::to_string(needed));
    pc.coords.insert(pc.coords.end(), xyz, xyz + dim);
  }
  pc.n = pc.coords.size() / static_cast<std::size_t>(dim);
  return pc;
}

std::vector<double> read_text_column(const std::string& path, const std::string& name, const FramePlace& frame) {
  if (is_xyz_file(path)) return read_xyz_column(path, name, frame);
  const std::string text = read_file_bytes(path);
  Lines lines(text);
  std::string_view line;
  std::size_t line_no = 0;
  if (!lines.next(line, line_no)) fail(path, "no points");
  // The first content line must be a header naming the column.
  const TextLayout layout = text_layout(line);
  const char delim = layout.delim;
  const std::size_t col = find_column(path, layout, name, "scalars");

  std::vector<double> values;
  while (lines.next(line, line_no)) {
    Fields fs(line, delim);
    std::string_view f;
    std::size_t c = 0;
    bool found = false;
    while (fs.next(f)) {
      if (c++ == col) {
        found = true;
        break;
      }
    }
    if (!found)
      fail(path, "line " + std::to_string(line_no) + " has no column " + std::to_string(col + 1) + " ('" + name + "')");
    double v = 0;
    if (!parse_double(f, v))
      fail(path, "line " + std::to_string(line_no) + ": cannot parse '" + std::string(f) + "' in column '" + name +
                     "' as a number");
    values.push_back(v);
  }
  return values;
}

}  // namespace tessera::io::detail
