// LAMMPS dump files: the first frame's atoms in every coordinate style, the
// box (orthogonal and triclinic, periodic flags), columns as labels and
// scalars, and the errors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::FileBox;
using tessera::io::read_file_box;
using tessera::io::read_point_scalars;
using tessera::io::read_points;
using tessera::io::ReadOptions;

namespace {

// Three atoms of a box [-1, 3] x [0.5, 5.5] x [2, 8], periodic in x and y.
const double kX[3][3] = {{0.5, 1.0, 2.5}, {-0.75, 4.0, 7.5}, {2.25, 0.5, 3.0}};

std::string ortho(const std::string& columns, const std::string& rows, const char* flags = " pp pp fm") {
  return std::string("ITEM: TIMESTEP\n1500\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS") + flags +
         "\n-1 3\n0.5 5.5\n2 8\nITEM: ATOMS " + columns + "\n" + rows;
}

const char* kRows =
    "7 2 0.5 1 2.5 0.25\n"
    "3 1 -0.75 4 7.5 0.5\n"
    "5 2 2.25 0.5 3 0.125\n";

}  // namespace

TEST(LammpsDump, UnitsAndTimeBeforeTheTimestep) {
  // What LAMMPS writes with dump_modify units yes, time yes.
  TempDir dir;
  const std::string text = "ITEM: UNITS\nlj\nITEM: TIME\n0.5\n" +
                           ortho("id type x y z", "1 1 0.5 1 2.5\n2 1 -0.75 4 7.5\n3 1 2.25 0.5 3\n");
  const auto pc = read_points(dir.write("units.dump", text));
  EXPECT_EQ(pc.n, 3u);
  EXPECT_EQ(read_file_box(dir.file("units.dump"))->timestep, 1500);
}

TEST(LammpsDump, OrthogonalBoxAndAtomsInFileOrder) {
  TempDir dir;
  // Another frame after the first, and an item LAMMPS may add (UNITS).
  const std::string text =
      "ITEM: UNITS\nlj\n" + ortho("id type x y z radius", kRows) + "ITEM: TIMESTEP\n1600\nITEM: NUMBER OF ATOMS\n1\n";
  const std::string with_units = "ITEM: TIMESTEP\n1500\nITEM: UNITS\nlj\n" + text.substr(text.find("ITEM: NUMBER"));
  for (const std::string& name : {"a.dump", "a.lammpstrj"}) {
    const std::string p = dir.write(name, with_units);
    const auto pc = read_points(p, labels("type"));
    ASSERT_EQ(pc.n, 3u);
    EXPECT_EQ(pc.dim, 3);
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) EXPECT_EQ(pc.coords[static_cast<std::size_t>(3 * k + a)], kX[k][a]);
    EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{2, 1, 2}));
    EXPECT_EQ(read_point_scalars(p, "radius"), (std::vector<double>{0.25, 0.5, 0.125}));
    const auto box = read_file_box(p);
    ASSERT_TRUE(box.has_value());
    EXPECT_EQ(box->lo, (std::array<double, 3>{-1, 0.5, 2}));
    EXPECT_EQ(box->hi, (std::array<double, 3>{3, 5.5, 8}));
    EXPECT_EQ(box->periodic, (std::array<bool, 3>{true, true, false}));
    EXPECT_FALSE(box->triclinic);
    EXPECT_EQ(box->tilt, (std::array<double, 3>{0, 0, 0}));
    EXPECT_EQ(box->timestep, 1500);
  }
  // --dim 2 keeps x and y.
  ReadOptions two;
  two.dim = 2;
  const auto pc2 =
      read_points(dir.write("b.dump", ortho("id type x y z", "1 1 0.5 1 2.5\n2 1 -0.75 4 7.5\n3 1 2.25 0.5 3\n")), two);
  EXPECT_EQ(pc2.coords, (std::vector<double>{0.5, 1, -0.75, 4, 2.25, 0.5}));
  // Other formats declare no box.
  EXPECT_FALSE(read_file_box(dir.write("c.csv", "x,y,z\n0,0,0\n1,1,1\n")).has_value());
}

TEST(LammpsDump, CoordinateStyles) {
  TempDir dir;
  // Unwrapped coordinates are taken as they are (the periodic box wraps them).
  auto pc = read_points(dir.write("u.dump", ortho("id xu yu zu", "1 0.5 1 2.5\n2 -4.75 4 7.5\n3 2.25 10.5 3\n")));
  EXPECT_EQ(pc.coords[3], -4.75);
  EXPECT_EQ(pc.coords[7], 10.5);
  // Plain x y z are preferred to the others when several are written.
  pc = read_points(
      dir.write("both.dump", ortho("xs ys zs x y z", "0 0 0 0.5 1 2.5\n0 0 0 -0.75 4 7.5\n0 0 0 2.25 0.5 3\n")));
  EXPECT_EQ(pc.coords[0], 0.5);
  // Scaled: fractions of the box (dyadic here, so exact).
  pc = read_points(
      dir.write("s.dump", ortho("id type xs ys zs", "1 1 0.375 0.1 0.25\n2 1 0 0.7 0.9375\n3 1 0.8125 0 0.125\n")));
  EXPECT_EQ(pc.coords[0], 0.5);    // -1 + 0.375 * 4
  EXPECT_EQ(pc.coords[2], 3.5);    // 2 + 0.25 * 6
  EXPECT_EQ(pc.coords[5], 7.625);  // 2 + 0.9375 * 6
  EXPECT_EQ(pc.coords[6], 2.25);   // -1 + 0.8125 * 4
}

TEST(LammpsDump, TriclinicBoxFromItsBoundingBox) {
  TempDir dir;
  // Lattice vectors a = (4, 0, 0), b = (1.5, 5, 0), c = (-0.5, 0.75, 6) from
  // (-1, 0.5, 2): LAMMPS writes the bounding box, xlo_bound = -1 + min(0,
  // 1.5, -0.5, 1) = -1.5, xhi_bound = 3 + max(0, 1.5, -0.5, 1) = 4.5,
  // ylo_bound = 0.5, yhi_bound = 5.5 + 0.75 = 6.25.
  const std::string text =
      "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS xy xz yz pp pp pp\n"
      "-1.5 4.5 1.5\n0.5 6.25 -0.5\n2 8 0.75\nITEM: ATOMS id type xs ys zs\n"
      "1 1 0.5 0.5 0.5\n2 1 0 0 1\n";
  const std::string p = dir.write("t.lammpstrj", text);
  const auto box = read_file_box(p);
  ASSERT_TRUE(box.has_value());
  EXPECT_TRUE(box->triclinic);
  EXPECT_EQ(box->lo, (std::array<double, 3>{-1, 0.5, 2}));
  EXPECT_EQ(box->hi, (std::array<double, 3>{3, 5.5, 8}));
  EXPECT_EQ(box->tilt, (std::array<double, 3>{1.5, -0.5, 0.75}));
  EXPECT_EQ(box->periodic, (std::array<bool, 3>{true, true, true}));
  const auto pc = read_points(p);
  // The centre: lo + (a + b + c) / 2; the second atom: lo + c.
  EXPECT_EQ(pc.coords, (std::vector<double>{-1 + 2.5, 0.5 + 2.875, 5, -1.5, 1.25, 8}));
  // In 2D only the xy tilt exists.
  ReadOptions two;
  two.dim = 2;
  EXPECT_NE(input_error([&] { read_points(p, two); }).find("tilts along z"), std::string::npos);
}

TEST(LammpsDump, Errors) {
  TempDir dir;
  struct Case {
    std::string text, expect;
  };
  const std::string head = "ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n";
  const std::vector<Case> cases = {
      {"", "not a LAMMPS dump"},
      {"x y z\n0 0 0\n", "not a LAMMPS dump"},
      {"ITEM: TIMESTEP\n1\n", "ends before"},
      {"ITEM: TIMESTEP\nnoon\n", "timestep is not an integer"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n-2\n", "not a count"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: ATOMS x y z\n", "before the frame's BOX BOUNDS"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp\n0 1\n0 1\n0 1\n", "three boundary flags"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 nan\n0 1\n", "y bounds"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n1 1\n", "empty z range"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS xy xz yz pp pp pp\n0 1\n0 1\n0 1\n",
       "3 finite numbers"},
      {head + "ITEM: ATOMS\n", "names no columns"},
      {head + "ITEM: ATOMS id type\n1 1\n2 1\n", "no coordinate columns"},
      {head + "ITEM: ATOMS id xs ys\n1 0 0\n2 0 0\n", "no coordinate columns"},  // scaled needs all three
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\n", "the file ends at line 10, after 1 of the frame's 2 atoms"},
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\nITEM: TIMESTEP\n", "fewer atoms than NUMBER OF ATOMS"},
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0\n", "line 11: expected 4 values"},
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0 0 9\n", "expected 4 values"},
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 zero 0\n", "column 'y' is not a number: 'zero'"},
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 inf 0\n", "non-finite coordinate"},
      // Found by a fuzz of the readers: more atom lines than the count (an
      // atom was dropped silently), a corrupted ATOMS item (a later frame
      // was read silently), items twice, boundary flags that are none.
      {head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0 0\n3 1 1 1\n", "line 12: more atom lines than NUMBER OF ATOMS (2)"},
      {head + "ITEM: ATOM id x y z\n1 0 0 0\n2 0 0 0\n" + head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 1 1 1\n",
       "line 9: unknown item 'ATOM id x y z'"},
      {head + "ITEM: ATOMSX id x y z\n1 0 0 0\n2 0 0 0\n", "unknown item 'ATOMSX id x y z'"},
      {head + "ITEM: NOTES\nhello\nITEM: ATOMS id x y z\n1 0 0 0\n2 1 1 1\n", "unknown item 'NOTES'"},
      {"ITEM: TIMESTEP\n1\nITEM: TIMESTEP\n2\n", "line 3: ITEM: TIMESTEP again before ITEM: ATOMS"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS PP pp pp\n0 1\n0 1\n0 1\n", "flag 'PP' along x"},
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp fp pp\n0 1\n0 1\n0 1\n", "flag 'fp' along y"},
      // A count far beyond the file: an error, not its memory (48 GB asked).
      {"ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2147483647\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
       "ITEM: ATOMS x y z\n0 0 0\n",
       "after 1 of the frame's 2147483647 atoms"},
  };
  for (const Case& c : cases) {
    const std::string p = dir.write("e.dump", c.text);
    const std::string msg = input_error([&] { read_points(p); });
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.text << "\n-> " << msg;
    EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;  // names the file
  }
  // Labels must be integers in a column that exists; scalars likewise named.
  const std::string p = dir.write("l.dump", head + "ITEM: ATOMS id type q x y z\n1 1 0.5 0 0 0\n2 1.5 -1 1 1 1\n");
  EXPECT_NE(input_error([&] { read_points(p, labels("type")); }).find("1.5 is not an int32"), std::string::npos);
  EXPECT_NE(input_error([&] { read_points(p, labels("mol")); }).find("no column 'mol'"), std::string::npos);
  EXPECT_EQ(read_point_scalars(p, "q"), (std::vector<double>{0.5, -1}));
  EXPECT_NE(input_error([&] { read_point_scalars(p, "radius"); }).find("no column 'radius'"), std::string::npos);
  // A non-numeric column that is not asked for is fine (an element name).
  const auto pc = read_points(dir.write("el.dump", head + "ITEM: ATOMS id element x y z\n1 Cu 0 0 0\n2 Ni 1 1 1\n"));
  EXPECT_EQ(pc.n, 2u);
}

// A trajectory's first frame is read without the frames after it: here the
// file goes on to 64 GiB (sparse: NUL bytes), which reading whole would
// never do.
TEST(LammpsDump, FirstFrameOfAHugeTrajectory) {
  TempDir dir;
  const std::string p = dir.write("huge.lammpstrj", ortho("id type x y z radius", kRows) + "ITEM: TIMESTEP\n");
  try {
    std::filesystem::resize_file(p, std::uintmax_t{1} << 36);
  } catch (const std::filesystem::filesystem_error& e) {
    GTEST_SKIP() << "no sparse 64 GiB file here: " << e.what();
  }
  const auto pc = read_points(p, labels("type"));
  EXPECT_EQ(pc.n, 3u);
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{2, 1, 2}));
  EXPECT_EQ(read_point_scalars(p, "radius"), (std::vector<double>{0.25, 0.5, 0.125}));
  EXPECT_TRUE(read_file_box(p).has_value());
}

// A trajectory's frames one after another (read_frame from each one's
// offset): atoms, boxes and timesteps per frame, the last one said, and a
// later frame's error naming its line in the whole file.
TEST(LammpsDump, FramesOneAfterAnother) {
  TempDir dir;
  std::string text;
  const int counts[3] = {3, 5, 2};
  for (int s = 0; s < 3; ++s) {
    text += "ITEM: TIMESTEP\n" + std::to_string(100 * s) + "\nITEM: NUMBER OF ATOMS\n" + std::to_string(counts[s]) +
            "\nITEM: BOX BOUNDS pp pp " + (s == 1 ? "ff" : "pp") + "\n0 " + std::to_string(s + 1) + "\n0 1\n0 1\n" +
            "ITEM: ATOMS id type x y z\n";
    for (int k = 0; k < counts[s]; ++k)
      text += std::to_string(k + 1) + " " + std::to_string(s + 1) + " " + std::to_string(0.125 * k) + " 0.5 0.25\n";
    if (s == 0) text += "\n";  // a blank line between frames
  }
  const std::string p = dir.write("t.lammpstrj", text);
  std::uint64_t offset = 0;
  std::size_t line = 1;
  for (int s = 0; s < 3; ++s) {
    const auto f = tessera::io::read_frame(p, offset, line, labels("type"));
    ASSERT_EQ(f.points.n, static_cast<std::size_t>(counts[s])) << s;
    EXPECT_EQ(f.points.coords[3], 0.125);
    EXPECT_EQ(f.points.labels, std::vector<std::int32_t>(static_cast<std::size_t>(counts[s]), s + 1));
    ASSERT_TRUE(f.box.has_value());
    EXPECT_EQ(f.box->timestep, 100 * s);
    EXPECT_EQ(f.box->hi[0], s + 1);
    EXPECT_EQ(f.box->periodic[2], s != 1);
    EXPECT_EQ(f.last, s == 2) << s;
    offset = f.next_offset;
    line = f.next_line;
  }
  EXPECT_EQ(offset, text.size());
  // The second frame's 4th atom broken: its line in the file is named.
  std::string bad = text;
  const std::size_t at = bad.find("4 2 0.375");
  bad.replace(at, 9, "4 2 zero!");
  const std::string q = dir.write("bad.lammpstrj", bad);
  const auto f0 = tessera::io::read_frame(q);
  const std::size_t expected_line = static_cast<std::size_t>(std::count(bad.begin(), bad.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 1;
  const std::string msg = input_error([&] { tessera::io::read_frame(q, f0.next_offset, f0.next_line); });
  EXPECT_NE(msg.find("line " + std::to_string(expected_line) + ": column 'x' is not a number"), std::string::npos) << msg;
  // A file of another format has no frames.
  EXPECT_NE(input_error([&] { tessera::io::read_frame(dir.write("p.csv", "x,y\n0,0\n1,1\n")); }).find("not a trajectory"),
            std::string::npos);
}

// find_frame: any frame by its index from either end, read with its own box,
// labels and scalars; frames on the way are walked by their line counts, and
// a frame whose lines do not match its count is named by its line.
TEST(LammpsDump, FramesByIndex) {
  TempDir dir;
  std::string text;
  const int counts[4] = {3, 5, 2, 4};
  for (int s = 0; s < 4; ++s) {
    if (s == 2) text += "ITEM: UNITS\nlj\n";  // items before TIMESTEP
    text += "ITEM: TIMESTEP\n" + std::to_string(100 * s) + "\nITEM: NUMBER OF ATOMS\n" + std::to_string(counts[s]) +
            "\nITEM: BOX BOUNDS pp pp pp\n0 " + std::to_string(s + 1) + "\n0 1\n0 1\nITEM: ATOMS id type x y z r\n";
    for (int k = 0; k < counts[s]; ++k)
      text += std::to_string(k + 1) + " " + std::to_string(s + 1) + " " + std::to_string(0.125 * k) + " 0.5 0.25 " +
              std::to_string(s) + ".5\n";
    if (s == 0) text += "\n\n";  // blank lines between frames
  }
  const std::string p = dir.write("t.lammpstrj", text);
  // The frames' own starts, as read_frame walks them.
  std::vector<tessera::io::TrajectoryFrame> walked;
  for (std::uint64_t offset = 0, line = 1;;) {
    walked.push_back(tessera::io::read_frame(p, offset, line, labels("type")));
    offset = walked.back().next_offset;
    line = walked.back().next_line;
    if (walked.back().last) break;
  }
  ASSERT_EQ(walked.size(), 4u);
  for (int index = -4; index < 4; ++index) {
    const std::size_t s = static_cast<std::size_t>(index < 0 ? index + 4 : index);
    const tessera::io::FramePlace at = tessera::io::find_frame(p, index);
    EXPECT_EQ(at.index, s) << index;
    EXPECT_EQ(at.offset, s == 0 ? 0 : walked[s - 1].next_offset) << index;
    EXPECT_EQ(at.line, s == 0 ? 1 : walked[s - 1].next_line) << index;
    ReadOptions o = labels("type");
    o.frame = at;
    const auto pc = read_points(p, o);
    EXPECT_EQ(pc.coords, walked[s].points.coords) << index;
    EXPECT_EQ(pc.labels, std::vector<std::int32_t>(static_cast<std::size_t>(counts[s]), static_cast<int>(s) + 1));
    EXPECT_EQ(read_point_scalars(p, "r", at), std::vector<double>(static_cast<std::size_t>(counts[s]), s + 0.5));
    EXPECT_EQ(read_file_box(p, at)->hi[0], static_cast<double>(s + 1));
    EXPECT_EQ(read_file_box(p, at)->timestep, static_cast<std::int64_t>(100 * s));
  }
  for (const std::int64_t index : {std::int64_t{4}, std::int64_t{-5}, std::numeric_limits<std::int64_t>::min()})
    EXPECT_NE(input_error([&] { tessera::io::find_frame(p, index); })
                  .find("no frame " + std::to_string(index) + ": it has 4 frames (0 to 3, or -4 to -1 from the end)"),
              std::string::npos);
  // A frame with an atom line too few or too many, on the way to another.
  for (const char* edit : {"drop", "add"}) {
    std::string bad = text;
    const std::size_t at = bad.find("2 2 0.125000");
    if (std::string(edit) == "drop")
      bad.erase(at, bad.find('\n', at) + 1 - at);
    else
      bad.insert(at, "9 2 0.5 0.5 0.5 1.5\n");
    const std::string q = dir.write(std::string(edit) + ".dump", bad);
    const std::string msg = input_error([&] { tessera::io::find_frame(q, -1); });
    EXPECT_NE(msg.find(std::string(edit) == "drop" ? "fewer atoms than NUMBER OF ATOMS" : "more atom lines than"),
              std::string::npos)
        << msg;
    EXPECT_EQ(tessera::io::find_frame(q, 1).index, 1u);  // the broken frame is found; reading it fails
  }
  // Another format: only its one frame.
  const std::string csv = dir.write("p.csv", "x,y\n0,0\n1,1\n");
  EXPECT_NE(input_error([&] { tessera::io::find_frame(csv, 0); }).find("not a trajectory"), std::string::npos);
  ReadOptions second;
  second.frame.index = 1;
  EXPECT_NE(input_error([&] { read_points(csv, second); }).find("not a trajectory"), std::string::npos);
}

// A trajectory still being written: its last frame cut short, at a line
// break or within a line. The frames before it stay reachable from either
// end, and reading the cut frame names where the file ends. A frame after
// blank lines starts at its first item (the summary's "from line").
TEST(LammpsDump, LastFrameCutShort) {
  TempDir dir;
  std::string text;
  for (int s = 0; s < 4; ++s) {
    text += "ITEM: TIMESTEP\n" + std::to_string(s) +
            "\nITEM: NUMBER OF ATOMS\n4\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\nITEM: ATOMS id x y z\n"
            "1 0.1 0.2 0.3\n2 0.6 0.5 0.4\n3 0.3 0.8 0.2\n4 0.9 0.1 0.7\n";
    if (s == 0) text += "\n\n";
  }
  EXPECT_EQ(tessera::io::find_frame(dir.write("full.dump", text), 1).line, 16u);  // after two blank lines
  const std::size_t cut_at_line = text.rfind("3 0.3"), cut_in_line = text.size() - 5;
  for (const std::size_t cut : {cut_at_line, cut_in_line}) {
    const std::string p = dir.write("cut.dump", text.substr(0, cut));
    const auto all = tessera::io::find_frames(p);
    ASSERT_EQ(all.size(), 4u);
    EXPECT_EQ(all[2].atoms, 4);
    // Cut short of its atom lines: no count; cut inside its last line, the
    // walk (which counts lines, not values) takes the header's.
    EXPECT_EQ(all[3].atoms, cut == cut_at_line ? -1 : 4);
    const tessera::io::FramePlace before = tessera::io::find_frame(p, -2);
    EXPECT_EQ(before.index, 2u);
    ReadOptions o;
    o.frame = before;
    EXPECT_EQ(read_points(p, o).n, 4u);
    o.frame = tessera::io::find_frame(p, -1);
    const std::string msg = input_error([&] { read_points(p, o); });
    EXPECT_NE(msg.find(cut == cut_at_line ? "the file ends at line 52, after 2 of the frame's 4 atoms"
                                          : "line 54: expected 4 values"),
              std::string::npos)
        << msg;
  }
}
