// Standard input as a point file (stdin_input.hpp). The readers take paths,
// read some files twice (a structured .npy's header, threshold's scalars)
// and dispatch by extension, so standard input is copied into a temporary
// file named by the format sniffed from its first bytes, rather than read
// from the pipe by each reader.
#include "stdin_input.hpp"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>

#include "tessera/cells.hpp"
#include "tessera/io/atomic_file.hpp"

namespace tessera::cli {
namespace {

std::unique_ptr<io::TemporaryFile> g_spool;  // destroyed (the file removed) at exit

[[noreturn]] void cannot_read() {
  const int err = errno;
  throw InputError(std::string("cannot read stdin: ") + std::strerror(err));
}

/// The extension of the format whose signature `head` (the first bytes)
/// carries; .txt for anything else, the text reader's to judge.
std::string sniff(std::string_view head) {
  if (head.substr(0, 6) == "\x93NUMPY") return ".npy";
  if (head.substr(0, 4) == "ply\n" || head.substr(0, 5) == "ply\r\n") return ".ply";
  if (head.substr(0, 4) == "NRRD") return ".nrrd";
  if (head.substr(0, 4) == "LASF") return ".las";
  // Legacy VTK (before the PCD test, whose comment lines also start with '#').
  std::string first(head.substr(0, 22));
  for (char& c : first) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (first == "# vtk datafile version") return ".vtk";
  std::size_t k = head.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  while (k < head.size() && (head[k] == ' ' || head[k] == '\t' || head[k] == '\r' || head[k] == '\n')) ++k;
  const std::string_view body = head.substr(k);
  if (body.substr(0, 5) == "<?xml" || body.substr(0, 8) == "<VTKFile") {
    if (body.find("type=\"PolyData\"") != std::string_view::npos) return ".vtp";
    if (body.find("type=\"UnstructuredGrid\"") != std::string_view::npos) return ".vtu";
    if (body.find("type=\"ImageData\"") != std::string_view::npos) return ".vti";
    throw InputError("stdin: XML, but not a VTK PolyData, UnstructuredGrid or ImageData file");
  }
  if (body.substr(0, 10) == "ObjectType" || body.substr(0, 5) == "NDims") return ".mha";
  // LAMMPS: TIMESTEP first, or UNITS and TIME before it (dump_modify units, time).
  for (const std::string_view first : {"ITEM: TIMESTEP", "ITEM: UNITS", "ITEM: TIME"})
    if (body.substr(0, first.size()) == first) return ".dump";
  // PCD: comment lines, then VERSION (or FIELDS) opens the header.
  std::size_t at = k;
  while (at < head.size() && head[at] == '#') {
    const std::size_t nl = head.find('\n', at);
    if (nl == std::string_view::npos) break;
    at = nl + 1;
  }
  const std::string_view line = head.substr(at);
  if (line.substr(0, 8) == "VERSION " || line.substr(0, 7) == "FIELDS ") return ".pcd";
  return ".txt";
}

}  // namespace

std::string input_path(const std::string& arg) {
  if (arg != "-") return arg;
  if (g_spool) return g_spool->path();
  if (::isatty(STDIN_FILENO))
    throw InputError("INPUT '-' reads standard input, which is a terminal: pipe or redirect a point file into it");
  // Enough of the start for every signature (a VTK file's type attribute
  // follows its XML declaration and comments).
  std::string head(1 << 16, '\0');
  std::size_t have = 0;
  while (have < head.size()) {
    const std::size_t got = std::fread(head.data() + have, 1, head.size() - have, stdin);
    have += got;
    if (got == 0) {
      if (std::ferror(stdin)) cannot_read();
      break;
    }
  }
  head.resize(have);
  if (have == 0) throw InputError("stdin: no points (standard input is empty)");
  g_spool = std::make_unique<io::TemporaryFile>("stdin", sniff(head), [&](std::ostream& os) {
    os.write(head.data(), static_cast<std::streamsize>(head.size()));
    char buf[1 << 16];
    for (;;) {
      const std::size_t got = std::fread(buf, 1, sizeof buf, stdin);
      os.write(buf, static_cast<std::streamsize>(got));
      if (got < sizeof buf) {
        if (std::ferror(stdin)) cannot_read();
        break;
      }
    }
  });
  return g_spool->path();
}

std::string shown_path(const std::string& path) {
  return path == "-" || (g_spool && path == g_spool->path()) ? "stdin" : path;
}

std::string name_stdin(std::string message) {
  if (!g_spool) return message;
  const std::string& p = g_spool->path();
  for (std::size_t at = message.find(p); at != std::string::npos; at = message.find(p, at + 5))
    message.replace(at, p.size(), "stdin");
  return message;
}

}  // namespace tessera::cli
