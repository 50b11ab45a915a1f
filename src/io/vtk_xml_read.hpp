// Reading VTK XML files (.vti images; .vtp and .vtu point sets), after
// VTK's "VTK File Formats" (XML section):
//
//   <VTKFile type="ImageData|PolyData|UnstructuredGrid" byte_order="LittleEndian"
//            header_type="UInt32" compressor="vtkZLibDataCompressor">
//     ... <DataArray type="Float32" Name="name" NumberOfComponents="3"
//                    format="ascii|binary|appended" offset="0">...</DataArray> ...
//     <AppendedData encoding="raw|base64">_DATA</AppendedData>
//
// Binary data (inline base64, appended raw or base64) is a header of
// header_type integers then the bytes: uncompressed [nbytes] + data;
// zlib-compressed [nblocks, block size, last block size (0: full), compressed
// size of each block] + the blocks, each a zlib stream. VTK base64-encodes the
// header and the data either as one stream or as two (each padded), so the
// decoder restarts after every padded quantum. Private to src/io.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "image_detail.hpp"

namespace tessera::io::detail {

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::vector<std::size_t> children;  // indices into the element list
  std::size_t content_begin = 0, content_end = 0;  // text between the tags
};

struct BinaryLayout {
  std::size_t header_size = 4;  // UInt32 or UInt64
  bool big_endian = false;      // of the header integers (and the data)
  bool compressed = false;
};

/// A VTK XML file, read whole and scanned: its elements (element 0 is a
/// virtual root, whose child is <VTKFile>), and its arrays' values.
class VtkXmlFile {
 public:
  /// Reads and scans `path`; InputError unless <VTKFile type=...> is one of `types`.
  VtkXmlFile(const std::string& path, std::initializer_list<std::string_view> types);

  const std::string& path() const { return path_; }
  std::size_t size() const { return text_.size(); }  ///< the file's bytes
  const std::string& type() const { return type_; }
  std::size_t root() const { return root_; }  ///< the <VTKFile> element
  /// The first child of `parent` named `name`; 0 (the root) when none.
  std::size_t child(std::size_t parent, std::string_view name) const;
  std::vector<std::size_t> children(std::size_t parent, std::string_view name) const;
  const std::string* attr(std::size_t e, const char* name) const;

  /// The scalar type of DataArray `da`; InputError naming `array` when unsupported.
  ScalarType array_type(std::size_t da, const std::string& array) const;
  /// DataArray `da`'s first `count` values (ascii, inline base64 or appended;
  /// compressed or not), as bytes of array_type(da) in the byte order
  /// `big_endian` is set to. InputError when the data is short, longer than
  /// `count` (binary) or malformed.
  std::string array_bytes(std::size_t da, std::size_t count, const std::string& array, bool& big_endian) const;

 private:
  std::string path_, text_, type_;
  std::vector<XmlElement> elements_;
  std::size_t appended_ = std::string::npos;  ///< element index of <AppendedData>
  std::size_t appended_start_ = 0;            ///< offset of the byte after its '_'
  std::size_t root_ = 0;
  BinaryLayout layout_;
};

/// `bytes` (values of type `t` in byte order `big_endian`) as doubles.
std::vector<double> values_as_double(std::string_view bytes, ScalarType t, bool big_endian);

}  // namespace tessera::io::detail
