// --walls FILE (walls_file.hpp).
#include "walls_file.hpp"

#include <fstream>
#include <string>

#include "commands.hpp"  // extension, parse_number
#include "tessera/cells.hpp"  // InputError
#include "tessera/io/npy.hpp"

namespace tessera::cli {

namespace {

std::vector<std::vector<double>> from_npy(const std::string& path) {
  io::NpyArray a;
  try {
    a = io::read_npy_double(path);
  } catch (const InputError& e) {
    throw InputError(std::string("--walls: ") + e.what());
  }
  const bool one = a.shape.size() == 1;
  const std::size_t cols = one ? (a.shape.empty() ? 0 : a.shape[0]) : a.shape.size() == 2 ? a.shape[1] : 0;
  if (cols != 3 && cols != 4) {
    std::string shape = "(";
    for (std::size_t i = 0; i < a.shape.size(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape[i]);
    throw InputError("--walls " + path + ": expected an array of shape (k, 3) or (k, 4) (NX NY [NZ] D per wall), got " +
                     shape + (a.shape.size() == 1 ? ",)" : ")"));
  }
  std::vector<std::vector<double>> walls;
  for (std::size_t i = 0; i < a.as_double.size(); i += cols)
    walls.emplace_back(a.as_double.begin() + static_cast<std::ptrdiff_t>(i),
                       a.as_double.begin() + static_cast<std::ptrdiff_t>(i + cols));
  return walls;
}

std::vector<std::vector<double>> from_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("--walls " + path + ": cannot open the file");
  std::vector<std::vector<double>> walls;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::vector<double> row;
    std::size_t at = 0;
    auto is_sep = [](char c) { return c == ',' || c == ';' || c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
    while (at < line.size() && is_sep(line[at])) ++at;
    if (at == line.size() || line[at] == '#') continue;
    while (at < line.size()) {
      std::size_t end = at;
      while (end < line.size() && !is_sep(line[end])) ++end;
      const std::string word = line.substr(at, end - at);
      row.push_back(parse_number(word, "--walls " + path + ", line " + std::to_string(number), false));
      at = end;
      while (at < line.size() && is_sep(line[at])) ++at;
    }
    if (row.size() != 3 && row.size() != 4)
      throw InputError("--walls " + path + ", line " + std::to_string(number) + ": " + std::to_string(row.size()) +
                       " values; a wall has 3 (NX NY D) or 4 (NX NY NZ D)");
    walls.push_back(std::move(row));
  }
  if (in.bad()) throw InputError("--walls " + path + ": cannot read the file");
  return walls;
}

}  // namespace

std::vector<std::vector<double>> read_walls_file(const std::string& path) {
  std::vector<std::vector<double>> walls = extension(path) == ".npy" ? from_npy(path) : from_text(path);
  if (walls.empty()) throw InputError("--walls " + path + ": no walls in the file");
  return walls;
}

}  // namespace tessera::cli
