// XYZ files (chemistry's: count, comment, species and positions) and
// extended XYZ (Properties, Lattice, pbc, Origin): points, labels and
// scalars from properties, the box, and the errors.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::read_file_box;
using tessera::io::read_point_scalars;
using tessera::io::read_points;
using tessera::io::ReadOptions;

TEST(Xyz, PlainFramesAndEmptyComment) {
  TempDir dir;
  // An empty comment line, CRLF endings, velocities after the positions,
  // and a second frame (a trajectory: the first is read).
  const std::string text =
      "3\r\n\r\nO 0.0 0.0 0.125 1 2 3\r\nH 0.757 0.586 0.0\r\nH -0.757 0.586 0.5\r\n"
      "1\r\nnext frame\r\nO 9 9 9\r\n";
  for (const char* name : {"w.xyz", "w.txt"}) {
    const std::string p = dir.write(name, text);
    const auto pc = read_points(p);
    ASSERT_EQ(pc.n, 3u);
    EXPECT_EQ(pc.coords, (std::vector<double>{0, 0, 0.125, 0.757, 0.586, 0, -0.757, 0.586, 0.5}));
    EXPECT_FALSE(read_file_box(p).has_value());  // no Lattice: the default domain
  }
  ReadOptions two;
  two.dim = 2;
  EXPECT_EQ(read_points(dir.write("w2.xyz", text), two).coords,
            (std::vector<double>{0, 0, 0.757, 0.586, -0.757, 0.586}));
  // A comment that is free text with an '=' in it is still a comment.
  EXPECT_EQ(read_points(dir.write("c.xyz", "1\nE = -76.4 eV, a=b\nO 1 2 3\n")).n, 1u);
}

TEST(Xyz, CommentsThatLookLikeOtherThings) {
  TempDir dir;
  // A comment that is a number, atoms of numeric species: XYZ, not Qhull's
  // header (whose points have as many numbers as the smaller count).
  auto pc = read_points(dir.write("n.xyz", "3\n4\n1 0.1 0.2 0.3\n1 0.4 0.5 0.6\n2 0.7 0.8 0.9\n"));
  EXPECT_EQ(pc.coords, (std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}));
  pc = read_points(dir.write("q.txt", "3\n4\n0.1 0.2 0.3\n0.4 0.5 0.6\n0.7 0.8 0.9\n1 1 1\n"));  // Qhull's
  EXPECT_EQ(pc.n, 4u);
  // An extended XYZ comment past 64 KiB keeps its box.
  const std::string comment = "Lattice=\"2 0 0 0 3 0 0 0 4\" pbc=\"T T T\" note=\"" + std::string(70000, 'x') + "\"";
  const std::string p = dir.write("long.xyz", "1\n" + comment + "\nAr 1 1 1\n");
  ASSERT_TRUE(read_file_box(p).has_value());
  EXPECT_EQ(read_file_box(p)->hi, (std::array<double, 3>{2, 3, 4}));
  EXPECT_EQ(read_points(p).n, 1u);
}

TEST(Xyz, ExtendedLatticePropertiesAndPbc) {
  TempDir dir;
  const std::string text =
      "3\n"
      "Lattice=\"4.0 0.0 0.0 1.5 5.0 0.0 -0.5 0.75 6.0\" Origin=\"-1 0.5 2\" "
      "Properties=species:S:1:tag:I:1:pos:R:3:radius:R:1 pbc=\"T F T\" energy=-3.5\n"
      "Cu 7 0.5 1 2.5 0.25\n"
      "Ni 3 -0.75 4 7.5 0.5\n"
      "Cu 7 2.25 0.5 3 0.125\n";
  const std::string p = dir.write("e.xyz", text);
  const auto pc = read_points(p, labels("tag"));
  EXPECT_EQ(pc.coords, (std::vector<double>{0.5, 1, 2.5, -0.75, 4, 7.5, 2.25, 0.5, 3}));
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{7, 3, 7}));
  EXPECT_EQ(read_point_scalars(p, "radius"), (std::vector<double>{0.25, 0.5, 0.125}));
  EXPECT_EQ(read_point_scalars(p, "tag"), (std::vector<double>{7, 3, 7}));
  const auto box = read_file_box(p);
  ASSERT_TRUE(box.has_value());
  EXPECT_EQ(box->lo, (std::array<double, 3>{-1, 0.5, 2}));
  EXPECT_EQ(box->hi, (std::array<double, 3>{3, 5.5, 8}));
  EXPECT_EQ(box->tilt, (std::array<double, 3>{1.5, -0.5, 0.75}));
  EXPECT_EQ(box->periodic, (std::array<bool, 3>{true, false, true}));
  EXPECT_TRUE(box->triclinic);
  EXPECT_EQ(box->declared_by, "extended XYZ Lattice");
  // Without pbc a Lattice is periodic on every axis; without Origin it starts at 0.
  const auto b2 = read_file_box(dir.write("o.xyz", "1\nLattice=\"2 0 0 0 3 0 0 0 4\"\nAr 1 1 1\n"));
  ASSERT_TRUE(b2.has_value());
  EXPECT_EQ(b2->lo, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(b2->hi, (std::array<double, 3>{2, 3, 4}));
  EXPECT_EQ(b2->periodic, (std::array<bool, 3>{true, true, true}));
  EXPECT_FALSE(b2->triclinic);
}

TEST(Xyz, Errors) {
  TempDir dir;
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {"2\n\nC 0 0 0\n", "the file ends at line 3, after 1 of the frame's 2 atoms"},
      {"2\n\nC 0 0 0\nC 0 0\n", "line 4: expected 4 values per atom, got 3"},
      {"1\n\nC 0 zero 0\n", "'zero' is not a number"},
      {"1\nProperties=species:S:1:pos:R\nC 0 0 0\n", "name:type:count triples"},
      {"1\nProperties=species:S:1:pos:X:3\nC 0 0 0\n", "is not name:S|R|I|L:count"},
      {"1\nProperties=species:S:1:position:R:3\nC 0 0 0\n", "no pos:R:3"},
      {"1\nProperties=species:S:1:pos:R:3:q:R:1\nC 0 0 0\n", "expected 5 values per atom, got 4"},
      {"1\nLattice=\"1 0 0 0 1\"\nC 0 0 0\n", "Lattice needs 9 numbers, got 5"},
      {"1\nLattice=\"1 0 0 0 1 0 0 0 inf\"\nC 0 0 0\n", "not a finite number"},
      {"1\nLattice=\"0.7 0.7 0 -0.7 0.7 0 0 0 1\"\nC 0 0 0\n", "rotate the cell"},
      {"1\nLattice=\"1 0 0 0 1 0 0 0 1\" pbc=\"T T\"\nC 0 0 0\n", "pbc must be three of T and F"},
      {"1\nLattice=\"1 0 0 0 1 0 0 0 1\" pbc=\"T T yes\"\nC 0 0 0\n", "pbc must be three of T and F"},
      {"1\n\nC 0 0 nan\n", "non-finite coordinate"},
      // More atom lines than the count (an atom was dropped silently), and
      // a count far beyond the file (its memory was asked for).
      {"2\n\nH 0 0 0\nH 1 1 1\nH 2 2 2\n", "line 5: more atom lines than the frame's count (2)"},
      {"2147483647\n\nH 0 0 0\n", "after 1 of the frame's 2147483647 atoms"},
  };
  for (const Case& c : cases) {
    const std::string p = dir.write("e.xyz", c.text);
    const std::string msg = input_error([&] {
      read_file_box(p);
      read_points(p);
    });
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.text << "\n-> " << msg;
    EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
  }
  const std::string p = dir.write("l.xyz", "2\nProperties=species:S:1:pos:R:3:q:R:1\nC 0 0 0 0.5\nO 1 1 1 1\n");
  EXPECT_NE(input_error([&] { read_points(p, labels("q")); }).find("is R:1; need I:1"), std::string::npos);
  EXPECT_NE(input_error([&] { read_points(p, labels("species")); }).find("is S:1; need I:1"), std::string::npos);
  EXPECT_NE(input_error([&] { read_points(p, labels("tag")); }).find("no property 'tag'"), std::string::npos);
  EXPECT_NE(input_error([&] { read_point_scalars(p, "species"); }).find("need R:1 or I:1"), std::string::npos);
  // A Lattice that is no box of ours fails where the box is asked for, not
  // where only the atoms are: --bounds (bounds= in Python) can stand in.
  const std::string rot = dir.write("rot.xyz", "2\nLattice=\"0.7 0.7 0 -0.7 0.7 0 0 0 1\"\nC 0 0 0\nC 1 1 1\n");
  EXPECT_EQ(read_points(rot).n, 2u);
  EXPECT_NE(input_error([&] { tessera::io::read_frame(rot); }).find("rotate the cell"), std::string::npos);
  EXPECT_EQ(tessera::io::find_frame(rot, -1).index, 0u);
  // A column of single numbers is a one-column point file, not XYZ.
  EXPECT_NE(input_error([&] { read_points(dir.write("one.xyz", "1\n2\n3\n4\n")); }).find("1 coordinate column"),
            std::string::npos);
}

// The first frame of a trajectory that goes on to 64 GiB (sparse).
TEST(Xyz, FirstFrameOfAHugeTrajectory) {
  TempDir dir;
  const std::string p =
      dir.write("huge.xyz", "2\nLattice=\"2 0 0 0 3 0 0 0 4\" Properties=species:S:1:pos:R:3:q:R:1\nAr 1 1 1 0.5\nAr 0.5 2 3 1\n2\n");
  try {
    std::filesystem::resize_file(p, std::uintmax_t{1} << 36);
  } catch (const std::filesystem::filesystem_error& e) {
    GTEST_SKIP() << "no sparse 64 GiB file here: " << e.what();
  }
  EXPECT_EQ(read_points(p).coords, (std::vector<double>{1, 1, 1, 0.5, 2, 3}));
  EXPECT_EQ(read_point_scalars(p, "q"), (std::vector<double>{0.5, 1}));
  ASSERT_TRUE(read_file_box(p).has_value());
  EXPECT_EQ(read_file_box(p)->hi, (std::array<double, 3>{2, 3, 4}));
}

// XYZ frames one after another (blank lines between them), each with its
// own Lattice; a later frame's error names its line in the whole file.
TEST(Xyz, FramesOneAfterAnother) {
  TempDir dir;
  const std::string text =
      "2\nLattice=\"2 0 0 0 2 0 0 0 2\"\nAr 0 0 0\nAr 1 1 1\n\n"
      "3\nLattice=\"3 0 0 0 3 0 0 0 3\" pbc=\"T T F\"\nAr 0 0 0\nAr 1 1 1\nAr 2 2 2\n"
      "1\nplain comment\nAr 0.5 0.5 0.5\n";
  const std::string p = dir.write("t.xyz", text);
  std::uint64_t offset = 0;
  std::size_t line = 1;
  const std::size_t counts[3] = {2, 3, 1};
  for (int s = 0; s < 3; ++s) {
    const auto f = tessera::io::read_frame(p, offset, line);
    ASSERT_EQ(f.points.n, counts[s]) << s;
    EXPECT_EQ(f.box.has_value(), s < 2);
    if (s == 1) EXPECT_EQ(f.box->periodic, (std::array<bool, 3>{true, true, false}));
    EXPECT_EQ(f.last, s == 2);
    offset = f.next_offset;
    line = f.next_line;
  }
  EXPECT_EQ(line, 14u);
  const std::string q = dir.write("bad.xyz", text.substr(0, text.find("Ar 2 2 2")) + "Ar 2 two 2\n1\n\nAr 0 0 0\n");
  const auto f0 = tessera::io::read_frame(q);
  EXPECT_NE(input_error([&] { tessera::io::read_frame(q, f0.next_offset, f0.next_line); }).find("line 10: 'two' is not a number"),
            std::string::npos);
}

TEST(Xyz, FramesByIndex) {
  TempDir dir;
  const std::string text =
      "2\nLattice=\"2 0 0 0 2 0 0 0 2\" Properties=species:S:1:pos:R:3:r:R:1\nAr 0 0 0 0.5\nAr 1 1 1 0.5\n\n"
      "3\nLattice=\"3 0 0 0 3 0 0 0 3\" Properties=species:S:1:pos:R:3:r:R:1\nAr 0 0 0 1\nAr 1 1 1 1\nAr 2 2 2 1\n"
      "1\nplain comment\nAr 0.5 0.5 0.5\n";
  const std::string p = dir.write("t.xyz", text);
  const std::size_t lines[3] = {1, 6, 11};
  for (int index = -3; index < 3; ++index) {
    const std::size_t s = static_cast<std::size_t>(index < 0 ? index + 3 : index);
    const tessera::io::FramePlace at = tessera::io::find_frame(p, index);
    EXPECT_EQ(at.index, s);
    EXPECT_EQ(at.line, lines[s]);
    EXPECT_EQ(at.offset, s == 0 ? 0 : text.find(s == 1 ? "3\n" : "1\nplain"));
    tessera::io::ReadOptions o;
    o.frame = at;
    EXPECT_EQ(tessera::io::read_points(p, o).n, s == 0 ? 2u : s == 1 ? 3u : 1u);
    const auto box = tessera::io::read_file_box(p, at);
    EXPECT_EQ(box.has_value(), s < 2);
    if (s < 2) {
      EXPECT_EQ(box->hi[0], s == 0 ? 2.0 : 3.0);
      EXPECT_EQ(tessera::io::read_point_scalars(p, "r", at), std::vector<double>(s == 0 ? 2 : 3, s == 0 ? 0.5 : 1.0));
    }
  }
  EXPECT_NE(input_error([&] { tessera::io::find_frame(p, 3); }).find("no frame 3: it has 3 frames"), std::string::npos);
  // A count one short: its frame's next line is no count.
  std::string bad = text;
  bad.replace(bad.find("3\nLattice=\"3"), 1, "2");
  const std::string q = dir.write("bad.xyz", bad);
  const std::string msg = input_error([&] { tessera::io::find_frame(q, -1); });
  EXPECT_NE(msg.find("more atom lines than the frame's count (2)"), std::string::npos) << msg;
}

// A frame of 0 atoms is a frame (as a dump's): walked past, read as empty by
// read_frame, refused as "no points" by read_points.
TEST(Xyz, FrameOfNoAtoms) {
  TempDir dir;
  const std::string p = dir.write("z.xyz", "2\n\nC 0 0 0\nC 1 1 1\n0\nempty frame\n3\n\nC 0 0 0\nC 1 1 1\nC 2 0 1\n");
  const auto all = tessera::io::find_frames(p);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].atoms, 2);  // the walk went past every frame
  EXPECT_EQ(all[1].atoms, 0);
  EXPECT_EQ(all[2].atoms, 3);
  const auto at = tessera::io::find_frame(p, -1);
  EXPECT_EQ(at.index, 2u);
  EXPECT_EQ(at.line, 7u);
  tessera::io::ReadOptions o;
  o.frame = at;
  EXPECT_EQ(tessera::io::read_points(p, o).n, 3u);
  const auto mid = tessera::io::find_frame(p, 1);
  EXPECT_EQ(tessera::io::read_frame(p, mid.offset, mid.line).points.n, 0u);
  o.frame = mid;
  EXPECT_NE(input_error([&] { tessera::io::read_points(p, o); }).find("no points"), std::string::npos);
}
