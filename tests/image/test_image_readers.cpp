// Image readers against files written by VTK's own writers (vtkXMLImageDataWriter
// in every data mode, vtkMetaImageWriter raw and compressed) and hand-made NRRD
// headers (raw, gzip, ascii, detached data), all generated at test time by
// make_images.py under Debian's /usr/bin/python3 (python3-vtk9, numpy). Every
// voxel value, the sizes, spacing and origin are compared exactly. Malformed
// headers, truncated data and mismatched sizes must give one-line errors
// naming the file.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "image/image_test_util.hpp"
#include "tessera/io/image.hpp"

namespace {

using namespace image_test;
using tessera::ImageGeometry;
using tessera::LabelImage;
using tessera::ScalarImage;
using tessera::io::ImageReadOptions;
using tessera::io::read_label_image;
using tessera::io::read_scalar_image;

constexpr std::int64_t NX = 5, NY = 4, NZ = 3;
const std::array<double, 3> kSpacing{0.5, 0.25, 2.0};
const std::array<double, 3> kOrigin{2.0, -2.0, 5.0};

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t p = s.find(from);
  EXPECT_NE(p, std::string::npos) << "'" << from << "' not found";
  if (p != std::string::npos) s.replace(p, from.size(), to);
  return s;
}

class image_readers : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    const std::string script = (fs::path(__FILE__).parent_path() / "make_images.py").string();
    const std::string log = dir_->file("make_images.log");
    const std::string cmd = std::string(TESSERA_PYTHON) + " '" + script + "' '" + dir_->path().string() + "' > '" +
                            log + "' 2>&1";
    status_ = std::system(cmd.c_str());
    if (status_ != 0) log_ = slurp(log);
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    ASSERT_EQ(status_, 0) << "make_images.py failed (needs /usr/bin/python3 with python3-vtk9 and numpy):\n" << log_;
  }
  static std::string f(const std::string& name) { return dir_->file(name); }

  static void expect_geometry(const ImageGeometry& g, int dim, std::array<std::int64_t, 3> size,
                              std::array<double, 3> spacing, std::array<double, 3> origin) {
    EXPECT_EQ(g.dim, dim);
    EXPECT_EQ(g.size, size);
    for (int a = 0; a < dim; ++a) {
      EXPECT_EQ(g.spacing[static_cast<std::size_t>(a)], spacing[static_cast<std::size_t>(a)]) << "axis " << a;
      EXPECT_EQ(g.origin[static_cast<std::size_t>(a)], origin[static_cast<std::size_t>(a)]) << "axis " << a;
    }
  }
  /// The 3D label test image (optionally shifted by +20 for unsigned types).
  static void expect_labels(const std::string& name, int shift = 0, const ImageReadOptions& o = {}) {
    SCOPED_TRACE(name);
    LabelImage img;
    ASSERT_NO_THROW(img = read_label_image(f(name), o));
    expect_geometry(img.geometry, 3, {NX, NY, NZ}, kSpacing, kOrigin);
    ASSERT_EQ(img.labels.size(), static_cast<std::size_t>(NX * NY * NZ));
    int bad = 0;
    for (std::int64_t k = 0; k < NZ; ++k)
      for (std::int64_t j = 0; j < NY; ++j)
        for (std::int64_t i = 0; i < NX; ++i)
          bad += img.labels[img.geometry.index(i, j, k)] != label_at(i, j, k) + shift;
    EXPECT_EQ(bad, 0);
  }
  static void expect_field(const std::string& name, const ImageReadOptions& o = {}) {
    SCOPED_TRACE(name);
    ScalarImage img;
    ASSERT_NO_THROW(img = read_scalar_image(f(name), o));
    expect_geometry(img.geometry, 3, {NX, NY, NZ}, kSpacing, kOrigin);
    ASSERT_EQ(img.values.size(), static_cast<std::size_t>(NX * NY * NZ));
    int bad = 0;
    for (std::int64_t k = 0; k < NZ; ++k)
      for (std::int64_t j = 0; j < NY; ++j)
        for (std::int64_t i = 0; i < NX; ++i) bad += img.values[img.geometry.index(i, j, k)] != field_at(i, j, k);
    EXPECT_EQ(bad, 0);
  }

  static std::unique_ptr<TempDir> dir_;
  static int status_;
  static std::string log_;
};
std::unique_ptr<TempDir> image_readers::dir_;
int image_readers::status_ = -1;
std::string image_readers::log_;

// ------------------------------------------------------------------ VTK XML

TEST_F(image_readers, VtiEveryDataModeAndHeaderType) {
  for (const char* name :
       {"vti_ascii_none.vti", "vti_binary_none.vti", "vti_binary_zlib.vti", "vti_appended_raw_none.vti",
        "vti_appended_raw_zlib.vti", "vti_appended_base64_none.vti", "vti_appended_base64_zlib.vti",
        "vti_binary_none_h64.vti", "vti_binary_zlib_h64.vti", "vti_appended_raw_none_h64.vti",
        "vti_appended_raw_zlib_h64.vti", "vti_appended_base64_none_h64.vti", "vti_appended_base64_zlib_h64.vti"}) {
    expect_labels(name);  // the active scalars
    ImageReadOptions o;
    o.array = "field";  // the second array, after the first in the appended block
    expect_field(name, o);
  }
}

TEST_F(image_readers, VtiEveryScalarType) {
  for (const char* t : {"int8", "int16", "int32", "int64"}) expect_labels(std::string("vti_type_") + t + ".vti");
  for (const char* t : {"uint8", "uint16", "uint32"}) expect_labels(std::string("vti_type_") + t + ".vti", 20);
  expect_field("vti_type_float32.vti");
  expect_error(input_error([] { read_label_image(f("vti_type_float32.vti")); }),
               {"vti_type_float32.vti", "float32", "not a label image"});
}

TEST_F(image_readers, VtiActiveScalarsAndArrayChoice) {
  expect_field("vti_active_field.vti");  // active = field
  ImageReadOptions o;
  o.array = "labels";
  expect_labels("vti_active_field.vti", 0, o);
  o.array = "nope";
  expect_error(input_error([&] { read_label_image(f("vti_active_field.vti"), o); }),
               {"vti_active_field.vti", "no point data array named 'nope'", "labels", "field"});
}

TEST_F(image_readers, VtiPiecesAssembled) { expect_labels("vti_pieces.vti"); }

TEST_F(image_readers, Vti2D) {
  const LabelImage img = read_label_image(f("vti_2d.vti"));
  expect_geometry(img.geometry, 2, {NX, NY, 1}, kSpacing, kOrigin);
  for (std::int64_t j = 0; j < NY; ++j)
    for (std::int64_t i = 0; i < NX; ++i) EXPECT_EQ(img.labels[img.geometry.index(i, j)], byte_at(i, j, 0));
}

TEST_F(image_readers, VtiMultiComponentRejected) {
  expect_error(input_error([] { read_label_image(f("vti_vector.vti")); }),
               {"vti_vector.vti", "3 components", "multi-component"});
}

TEST_F(image_readers, VtiMalformed) {
  TempDir d;
  const std::string good = slurp(f("vti_binary_zlib.vti"));
  const std::string raw = slurp(f("vti_appended_raw_none.vti"));
  // Truncated appended data: the last array ends early.
  const std::string cut = d.write("cut.vti", raw.substr(0, raw.size() - 40));
  expect_error(input_error([&] { read_scalar_image(cut, {{}, {}, "field"}); }), {"cut.vti", "shorter"});
  // Truncated inline base64.
  const std::size_t p = good.find("format=\"binary\"");
  const std::size_t gt = good.find('>', p);
  const std::string b64cut = good.substr(0, gt + 30) + "\n</DataArray></PointData></Piece></ImageData></VTKFile>\n";
  const std::string bc = d.write("b64cut.vti", b64cut);
  expect_error(input_error([&] { read_label_image(bc); }), {"b64cut.vti"});
  // Unknown compressor.
  const std::string lz4 = d.write("lz4.vti", replace(good, "vtkZLibDataCompressor", "vtkLZ4DataCompressor"));
  expect_error(input_error([&] { read_label_image(lz4); }), {"lz4.vti", "unsupported compressor"});
  // Missing WholeExtent, rotated direction.
  const std::string nowe = d.write("nowe.vti", replace(good, "WholeExtent=", "Whole="));
  expect_error(input_error([&] { read_label_image(nowe); }), {"nowe.vti", "WholeExtent"});
  const std::string rot =
      d.write("rot.vti", replace(good, "Direction=\"1 0 0 0 1 0 0 0 1\"", "Direction=\"0 1 0 1 0 0 0 0 1\""));
  expect_error(input_error([&] { read_label_image(rot); }), {"rot.vti", "Direction", "rotated"});
  // A piece extent that does not match the data (mismatched sizes).
  const std::string big = d.write("big.vti", replace(replace(good, "WholeExtent=\"2 6", "WholeExtent=\"2 7"),
                                                     "Extent=\"2 6", "Extent=\"2 7"));
  expect_error(input_error([&] { read_label_image(big); }), {"big.vti", "mismatched sizes"});
  // Ascii with too few values.
  const std::string ascii = slurp(f("vti_ascii_none.vti"));
  const std::size_t a0 = ascii.find("format=\"ascii\"");
  const std::size_t a1 = ascii.find('>', a0) + 1;
  const std::string few = d.write("few.vti", ascii.substr(0, a1) + "1 2 3" + ascii.substr(ascii.find("</DataArray>", a1)));
  expect_error(input_error([&] { read_label_image(few); }), {"few.vti", "shorter"});
  // Broken XML, not ImageData.
  const std::string broken = d.write("broken.vti", "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\"");
  expect_error(input_error([&] { read_label_image(broken); }), {"broken.vti", "malformed XML"});
  const std::string poly = d.write("poly.vti", replace(good, "type=\"ImageData\"", "type=\"PolyData\""));
  expect_error(input_error([&] { read_label_image(poly); }), {"poly.vti", "PolyData"});
  // A corrupt compressed block.
  std::string corrupt = slurp(f("vti_appended_raw_zlib.vti"));
  corrupt[corrupt.size() - 60] ^= 0x5a;
  corrupt[corrupt.size() - 61] ^= 0x33;
  const std::string cz = d.write("corrupt.vti", corrupt);
  expect_error(input_error([&] { read_scalar_image(cz, {{}, {}, "field"}); }), {"corrupt.vti"});
}

// What sizes the image is checked before it is allocated (an image fuzz: a
// file of 480 bytes claiming 10^10 voxels in pieces took 20 GB before its
// refusal, and a block header claiming 10^11 bytes ended "out of memory").
TEST_F(image_readers, VtiClaimsBeyondTheFileRefusedFirst) {
  TempDir d;
  auto pieces = [](const std::string& whole) {
    std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
                    "<ImageData WholeExtent=\"" + whole + "\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n";
    for (const char* e : {"0 0 0 0 0 0", "1 1 0 0 0 0"})
      s += std::string("<Piece Extent=\"") + e + "\"><PointData Scalars=\"s\"><DataArray type=\"UInt8\" Name=\"s\" "
           "format=\"ascii\">1</DataArray></PointData></Piece>\n";
    return s + "</ImageData>\n</VTKFile>\n";
  };
  expect_error(input_error([&] { read_label_image(d.write("huge.vti", pieces("0 9999 0 9999 0 99"))); }),
               {"huge.vti", "has 10000000000 voxels, more than the file's"});
  expect_error(input_error([&] { read_label_image(d.write("gaps.vti", pieces("0 9 0 9 0 0"))); }),
               {"gaps.vti", "the Pieces do not cover WholeExtent"});
  // One zlib block of 100,000 bytes whose compressed size claims 2^40.
  std::string head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
                     "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n<ImageData WholeExtent=\"0 99 0 99 0 9\" "
                     "Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 99 0 99 0 9\"><PointData Scalars=\"s\">"
                     "<DataArray type=\"UInt8\" Name=\"s\" format=\"appended\" offset=\"0\"/></PointData></Piece>\n"
                     "</ImageData>\n<AppendedData encoding=\"raw\">_";
  for (const std::uint64_t v : {std::uint64_t{1}, std::uint64_t{100000}, std::uint64_t{0}, std::uint64_t{1} << 40})
    for (int k = 0; k < 8; ++k) head += static_cast<char>((v >> (8 * k)) & 0xff);
  const std::string claim = d.write("claim.vti", head + std::string(300, 'x') + "\n</AppendedData>\n</VTKFile>\n");
  expect_error(input_error([&] { read_label_image(claim); }),
               {"claim.vti", "its compressed blocks take more than the", "data shorter than the header says"});
}

// ------------------------------------------------------------------ NIfTI

// The test geometry stored plainly and with flipped axes (negative steps in
// the sform, a qform's qfac, a qform turning y and z), gzipped, big-endian,
// as a header/image pair and as NIfTI-2: every one reads back to the same
// image, each flipped axis reversed.
// Axes stored with negative steps in the other formats (NRRD's space
// directions, MetaImage's TransformMatrix, .vti's Direction, checked against
// VTK's own index-to-world map in make_images.py's geometry): reversed on
// reading, the same image. They were refused as "flipped". So are VTK
// images with negative spacings (until stop 84 refused as "spacing ... must
// be > 0"), which VTK's readers place at Origin + i Spacing.
TEST_F(image_readers, FlippedAxesReadReversed) {
  for (const char* name :
       {"nrrd_flipx.nrrd", "meta_flipy.mha", "vti_flipxz.vti", "vti_negspacing.vti", "legacy_negspacing.vtk"})
    expect_labels(name);
}

// Legacy VTK images (STRUCTURED_POINTS, VTK's own writer in both modes):
// the first array of one component (the active scalars), or the one named.
TEST_F(image_readers, LegacyVtkImages) {
  ImageReadOptions o;
  o.array = "field";
  for (const char* name : {"legacy_ascii.vtk", "legacy_binary.vtk"}) {
    expect_labels(name);
    expect_field(name, o);
  }
  o.array = "none";
  expect_error(input_error([&] { read_label_image(f("legacy_binary.vtk"), o); }),
               {"legacy_binary.vtk", "no point data array 'none' (arrays: 'labels', 'field')"});
}

TEST_F(image_readers, NiftiFlipsVersionsAndEncodings) {
  for (const char* name : {"nifti1_sform.nii", "nifti1_flipx.nii.gz", "nifti1_qfac_be.nii", "nifti1_pair.hdr"})
    expect_labels(name);
  expect_field("nifti2_field.nii");
  expect_field("nifti1_scaled.nii.gz");  // float32 values times scl_slope plus scl_inter
  expect_error(input_error([] { read_label_image(f("nifti1_scaled.nii.gz")); }),
               {"nifti1_scaled.nii.gz", "scl_slope/scl_inter scale the values (0.5, 0.125)"});
  expect_error(input_error([] { read_label_image(f("nifti1_rotated.nii")); }),
               {"nifti1_rotated.nii", "rotates or permutes the axes"});
  expect_error(input_error([] { read_label_image(f("nifti1_4d.nii")); }),
               {"nifti1_4d.nii", "a 4D NIfTI image (dim[4] = 2", "extract one 3D volume"});
  expect_error(input_error([] { read_label_image(f("analyze.nii")); }), {"analyze.nii", "Analyze 7.5"});
}

TEST_F(image_readers, NiftiMalformed) {
  TempDir d;
  const std::string good = slurp(f("nifti1_sform.nii"));
  auto check = [&](const std::string& name, const std::string& bytes, std::initializer_list<std::string_view> parts) {
    const std::string p = d.write(name, bytes);
    expect_error(input_error([&] { read_label_image(p); }), parts);
    expect_error(input_error([&] { read_label_image(p); }), {name});
  };
  auto patched = [&](std::size_t at, std::string_view with) {
    std::string s = good;
    s.replace(at, with.size(), with);
    return s;
  };
  check("short.nii", good.substr(0, 200), {"not a NIfTI file"});
  check("size.nii", patched(0, std::string("\x10\x01\0\0", 4)), {"neither 348 nor 540"});
  check("cut.nii", good.substr(0, good.size() - 10), {"the data ends 10 bytes short", "60 voxels of int16"});
  check("type.nii", patched(70, std::string("\x80\0", 2)), {"datatype 128 is not supported"});
  check("bitpix.nii", patched(72, std::string("\x20\0", 2)), {"bitpix 32 does not match its datatype (int16)"});
  check("offset.nii", patched(108, std::string("\0\0\x80\x42", 4)), {"vox_offset 64 lies inside the header"});
  check("dim0.nii", patched(40, std::string("\x09\0", 2)), {"dim[0] must be 1 to 7, got 9"});
  check("zero.nii", patched(280, std::string(4, '\0')), {"voxel size along x is 0"});
  // A slope with a NaN intercept made every voxel NaN (nibabel refuses it).
  const std::string nan_inter = d.write("nan.nii", patched(112, std::string("\0\0\0\x40\0\0\xc0\x7f", 8)));
  expect_error(input_error([&] { tessera::io::read_scalar_image(nan_inter); }),
               {"nan.nii", "scl_slope 2 with an intercept scl_inter that is not finite"});
  // A header claiming a huge image over no data: refused, nothing sized by it.
  std::string huge = good.substr(0, 352);
  huge.replace(42, 6, std::string("\xff\x7f\xff\x7f\x01\0", 6));  // 32767 x 32767 x 1
  check("huge.nii", huge, {"the data ends"});
  // The pair's image missing.
  d.write("lone.hdr", slurp(f("nifti1_pair.hdr")));
  expect_error(input_error([&] { read_label_image(d.file("lone.hdr")); }), {"lone.hdr", "cannot open data file", "lone.img"});
}

// ------------------------------------------------------------------ MetaImage

TEST_F(image_readers, MetaImageRawAndCompressed) {
  for (const char* name : {"meta_raw.mha", "meta_raw.mhd", "meta_zlib.mha", "meta_zlib.mhd"}) expect_labels(name);
  expect_field("meta_field_raw.mha");
  expect_field("meta_field_zlib.mha");
}

TEST_F(image_readers, MetaImageMalformed) {
  TempDir d;
  const std::string good = slurp(f("meta_raw.mha"));
  const std::string header = good.substr(0, good.size() - static_cast<std::size_t>(NX * NY * NZ * 2));
  const std::string data = good.substr(header.size());
  auto check = [&](const std::string& name, const std::string& bytes, std::initializer_list<std::string_view> parts) {
    const std::string p = d.write(name, bytes);
    expect_error(input_error([&] { read_label_image(p); }), parts);
    expect_error(input_error([&] { read_label_image(p); }), {name});
  };
  check("short.mha", good.substr(0, good.size() - 7), {"shorter", "60 voxels"});
  check("long.mha", good + "xx", {"mismatched sizes"});
  check("rot.mha", replace(header, "TransformMatrix = 1 0 0 0 1 0 0 0 1", "TransformMatrix = 0 1 0 1 0 0 0 0 1") + data,
        {"TransformMatrix", "rotated"});
  check("chan.mha", replace(header, "ElementType", "ElementNumberOfChannels = 3\nElementType") + data,
        {"multi-component"});
  check("nodim.mha", replace(header, "DimSize = 5 4 3\n", "") + data, {"DimSize"});
  check("baddim.mha", replace(header, "DimSize = 5 4 3", "DimSize = 5 4") + data, {"DimSize"});
  check("type.mha", replace(header, "MET_SHORT", "MET_STRING") + data, {"unsupported", "MET_STRING"});
  check("nofile.mha", replace(header, "ElementDataFile = LOCAL\n", ""), {"ElementDataFile"});
  check("binary.mha", replace(header, "ElementDataFile = LOCAL\n", "") + "\x01\x02\x7f\n", {"malformed", "line '?" "?" "?'"});
  check("junk.mha", "hello world\n", {"malformed"});
  const std::string zgood = slurp(f("meta_zlib.mha"));
  std::string zbad = zgood;
  zbad[zbad.size() - 10] ^= 0x55;
  zbad[zbad.size() - 11] ^= 0x55;
  check("zbad.mha", zbad, {});
  check("zcut.mha", zgood.substr(0, zgood.size() - 10), {"compressed"});
  // A detached file that is missing.
  const std::string mhd = slurp(f("meta_raw.mhd"));
  d.write("gone.mhd", replace(mhd, "meta_raw.raw", "no_such.raw"));
  expect_error(input_error([&] { read_label_image(d.file("gone.mhd")); }), {"gone.mhd", "cannot open data file", "no_such.raw"});
}

// ------------------------------------------------------------------ NRRD

TEST_F(image_readers, NrrdEncodingsAndDetachedData) {
  for (const char* name : {"nrrd_raw.nrrd", "nrrd_gzip.nrrd", "nrrd_big.nrrd", "nrrd_ascii.nrrd", "nhdr_raw.nhdr",
                           "nhdr_gzip.nhdr"})
    expect_labels(name);
  expect_field("nrrd_field.nrrd");
  const LabelImage img = read_label_image(f("nrrd_2d.nrrd"));
  expect_geometry(img.geometry, 2, {NX, NY, 1}, {0.5, 0.25, 1}, {0, 0, 0});
  for (std::int64_t j = 0; j < NY; ++j)
    for (std::int64_t i = 0; i < NX; ++i) EXPECT_EQ(img.labels[img.geometry.index(i, j)], byte_at(i, j, 0));
}

TEST_F(image_readers, NrrdMalformed) {
  TempDir d;
  const std::string good = slurp(f("nrrd_raw.nrrd"));
  const std::size_t blank = good.find("\n\n") + 2;
  const std::string header = good.substr(0, blank);
  const std::string data = good.substr(blank);
  auto check = [&](const std::string& name, const std::string& bytes, std::initializer_list<std::string_view> parts) {
    const std::string p = d.write(name, bytes);
    expect_error(input_error([&] { read_label_image(p); }), parts);
    expect_error(input_error([&] { read_label_image(p); }), {name});
  };
  check("magic.nrrd", replace(good, "NRRD0004", "NRRX0004"), {"not a NRRD file"});
  check("nosizes.nrrd", replace(header, "sizes: 5 4 3\n", "") + data, {"sizes"});
  check("sizes.nrrd", replace(header, "sizes: 5 4 3", "sizes: 5 4") + data, {"sizes"});
  check("zero.nrrd", replace(header, "sizes: 5 4 3", "sizes: 5 0 3") + data, {"sizes"});
  check("bzip.nrrd", replace(header, "encoding: raw", "encoding: bzip2") + data, {"unsupported NRRD encoding", "bzip2"});
  check("short.nrrd", good.substr(0, good.size() - 5), {"shorter", "60 voxels"});
  check("long.nrrd", good + "abc", {"mismatched sizes"});
  check("rot.nrrd", replace(header, "(0.5,0,0) (0,0.25,0)", "(0,0.5,0) (0.25,0,0)") + data, {"axis-aligned", "rotated"});
  check("vector.nrrd", replace(header, "kinds: domain", "kinds: vector") + data, {"multi-component", "vector"});
  check("dim4.nrrd", replace(header, "dimension: 3", "dimension: 4") + data, {"dimension 4"});
  check("endian.nrrd", replace(header, "endian: little\n", "") + data, {"endian"});
  check("type.nrrd", replace(header, "type: short", "type: block") + data, {"unsupported NRRD type", "block"});
  check("line.nrrd", replace(header, "type: short", "type short") + data, {"malformed NRRD header line"});
  check("twice.nrrd", replace(header, "type: short", "type: short\ntype: int") + data, {"given twice"});
  // Fields NRRD does not define (a misspelling) were ignored: a unit grid at 0.
  check("typo.nrrd", replace(header, "type: short", "type: short\nspacing: 2 2 2") + data,
        {"unknown NRRD field 'spacing' (a misspelling?)"});
  check("mins.nrrd", replace(header, "type: short", "type: short\naxis mins: 1 2 3") + data,
        {"both 'axis mins' or 'axis maxs' and 'space directions'"});
  const std::string gz = slurp(f("nrrd_gzip.nrrd"));
  check("gzcut.nrrd", gz.substr(0, gz.size() - 12), {"gzip data"});
  const std::size_t gzb = gz.find("\n\n") + 2;
  check("gzjunk.nrrd", gz.substr(0, gzb) + std::string(40, 'x'), {"gzip data"});
  const std::string nhdr = slurp(f("nhdr_gzip.nhdr"));
  d.write("gone.nhdr", replace(nhdr, "nhdr_gzip.raw.gz", "nothere.raw.gz"));
  expect_error(input_error([&] { read_label_image(d.file("gone.nhdr")); }), {"gone.nhdr", "cannot open data file", "nothere.raw.gz"});
  // A data file, or the image itself, that never ends (a device): refused at
  // once, where it was read until memory ran out.
  d.write("zero.nhdr", replace(nhdr, "nhdr_gzip.raw.gz", "/dev/zero"));
  expect_error(input_error([&] { read_label_image(d.file("zero.nhdr")); }), {"zero.nhdr", "/dev/zero", "a device"});
  // A FIFO named as the data file blocked until something wrote to it.
  ASSERT_EQ(::mkfifo(d.file("pipe.raw").c_str(), 0600), 0);
  d.write("fifo.nhdr", replace(nhdr, "nhdr_gzip.raw.gz", "pipe.raw"));
  expect_error(input_error([&] { read_label_image(d.file("fifo.nhdr")); }), {"fifo.nhdr", "pipe.raw", "a FIFO"});
  std::filesystem::create_symlink("/dev/zero", d.path() / "endless.nrrd");
  expect_error(input_error([&] { read_label_image(d.file("endless.nrrd")); }), {"endless.nrrd", "a device"});
  std::filesystem::create_symlink("/dev/zero", d.path() / "endless.npy");
  expect_error(input_error([&] { tessera::io::read_points(d.file("endless.npy")); }), {"endless.npy", "a device"});
  // Options that only .vti understands.
  ImageReadOptions o;
  o.array = "x";
  expect_error(input_error([&] { read_label_image(f("nrrd_raw.nrrd"), o); }), {"nrrd_raw.nrrd", "array"});
}

// Axis mins place the grid as teem does (cell-centred by default: the first
// sample half a spacing above the min; node-centred at it); without
// spacings, axis maxs give them. And teem's byte skip in ascii data.
TEST_F(image_readers, NrrdAxisMinsAndAsciiByteSkip) {
  TempDir d;
  const std::string head = "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 3 2\nencoding: ascii\n";
  auto geometry = [&](const std::string& name, const std::string& fields) {
    return tessera::io::read_scalar_image(d.write(name, head + fields + "\n1 2 3 4 5 6\n")).geometry;
  };
  auto g = geometry("node.nrrd", "spacings: 0.5 2\naxis mins: 10 20\ncenters: node node\n");
  EXPECT_EQ(g.origin[0], 10);
  EXPECT_EQ(g.origin[1], 20);
  EXPECT_EQ(g.spacing[0], 0.5);
  g = geometry("cell.nrrd", "spacings: 0.5 2\naxis mins: 10 20\n");
  EXPECT_EQ(g.origin[0], 10.25);
  EXPECT_EQ(g.origin[1], 21);
  g = geometry("maxs.nrrd", "axis mins: 0 0\naxis maxs: 3 1\ncenters: cell node\n");
  EXPECT_EQ(g.spacing[0], 1);  // 3 cells over [0, 3]
  EXPECT_EQ(g.spacing[1], 1);  // 2 nodes over [0, 1]
  EXPECT_EQ(g.origin[0], 0.5);
  EXPECT_EQ(g.origin[1], 0);
  expect_error(input_error([&] { geometry("half.nrrd", "axis maxs: 3 1\n"); }), {"'axis maxs' without 'axis mins'"});
  expect_error(input_error([&] { geometry("ctr.nrrd", "axis mins: 0 0\ncenters: cell edge\n"); }),
               {"centering 'edge'"});
  const std::string skip = d.write("skip.nrrd", "NRRD0004\ntype: int\ndimension: 2\nsizes: 2 2\nbyte skip: 4\n"
                                                "encoding: ascii\n\n99991 2 3 4\n");
  EXPECT_EQ(tessera::io::read_scalar_image(skip).values, (std::vector<double>{1, 2, 3, 4}));
}

// ------------------------------------------------------------------ .npy and options

TEST_F(image_readers, NpyWithGeometryOptions) {
  ImageReadOptions o;
  o.spacing = kSpacing;
  o.origin = kOrigin;
  expect_labels("npy_labels.npy", 0, o);
  expect_field("npy_field.npy", o);
  const LabelImage plain = read_label_image(f("npy_labels.npy"));
  expect_geometry(plain.geometry, 3, {NX, NY, NZ}, {1, 1, 1}, {0, 0, 0});
  const LabelImage img2 = read_label_image(f("npy_2d.npy"));
  expect_geometry(img2.geometry, 2, {NX, NY, 1}, {1, 1, 1}, {0, 0, 0});
  EXPECT_EQ(img2.labels[img2.geometry.index(3, 2)], byte_at(3, 2, 0));
  expect_error(input_error([] { read_label_image(f("npy_field.npy")); }), {"npy_field.npy", "float", "label image"});
  // Overrides replace what the file says.
  o.spacing = std::array<double, 3>{1, 2, 3};
  o.origin = std::array<double, 3>{-1, -2, -3};
  const LabelImage v = read_label_image(f("vti_binary_zlib.vti"), o);
  expect_geometry(v.geometry, 3, {NX, NY, NZ}, {1, 2, 3}, {-1, -2, -3});
  o.spacing = std::array<double, 3>{1, 0, 3};
  expect_error(input_error([&] { read_label_image(f("npy_labels.npy"), o); }), {"npy_labels.npy", "spacing"});
}

TEST(image_readers_no_python, BadFilesAndShapes) {
  TempDir d;
  expect_error(input_error([&] { read_label_image(d.file("missing.nrrd")); }), {"cannot open", "missing.nrrd"});
  const std::string png = d.write("x.png", "png");
  expect_error(input_error([&] { read_label_image(png); }), {"x.png", "unknown image extension"});
  // .npy with 1 or 4 dimensions, and int64 labels out of int32 range.
  auto npy = [&](const std::string& name, const std::string& descr, const std::string& shape, std::size_t bytes) {
    std::string dict = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
    std::string h = std::string("\x93NUMPY\x01\x00", 8);
    std::string body = dict;
    while ((10 + body.size() + 1) % 64) body += ' ';
    body += '\n';
    h += static_cast<char>(body.size() & 0xff);
    h += static_cast<char>(body.size() >> 8);
    return d.write(name, h + body + std::string(bytes, '\0'));
  };
  const std::string one = npy("one.npy", "<i4", "(6,)", 24);
  expect_error(input_error([&] { read_label_image(one); }), {"one.npy", "(ny, nx) or (nz, ny, nx)"});
  const std::string four = npy("four.npy", "<i4", "(1, 2, 2, 2)", 32);
  expect_error(input_error([&] { read_label_image(four); }), {"four.npy", "4 dimensions"});
  const std::string empty = npy("empty.npy", "<i4", "(0, 3)", 0);
  expect_error(input_error([&] { read_label_image(empty); }), {"empty.npy", "empty"});
  std::string big = "\x93NUMPY\x01\x00";
  {
    std::string dict = "{'descr': '<i8', 'fortran_order': False, 'shape': (1, 2), }";
    while ((10 + dict.size() + 1) % 64) dict += ' ';
    dict += '\n';
    big = std::string("\x93NUMPY\x01\x00", 8) + static_cast<char>(dict.size()) + '\0' + dict;
    const std::int64_t v[2] = {5, std::int64_t(1) << 40};
    big.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  const std::string bigp = d.write("big.npy", big);
  expect_error(input_error([&] { read_label_image(bigp); }), {"big.npy", "does not fit in int32"});
  EXPECT_NO_THROW(read_scalar_image(bigp));
}

}  // namespace
