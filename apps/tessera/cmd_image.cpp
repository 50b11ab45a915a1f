// The image subcommands `sample-image` and `probe` (see commands.hpp). Each
// checks its arguments and output path before reading anything, reads the
// image (io/image.hpp), runs the library function, writes atomically and
// prints a one-line summary.
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "stdin_input.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/image.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"
#include "tessera/prep/probe.hpp"
#include "tessera/prep/sample_image.hpp"

namespace tessera::cli {
namespace {

/// `what`: which data the command takes (labels: integer types only).
std::string image_help(const char* what) {
  return std::string("Image of ") + what +
         ": .npy (shape (ny, nx) or (nz, ny, nx)), .nrrd/.nhdr (raw, gzip, ascii), .mha/.mhd (MetaImage, raw or "
         "compressed), .vti (VTK XML ImageData, any data mode), .vtk (legacy VTK STRUCTURED_POINTS) or .nii/.nii.gz/.hdr "
         "(NIfTI-1 or -2; flipped axes are reversed, rotated ones refused)";
}

void add_read_options(CLI::App* app, ImageReadArgs& r) {
  // One comma-separated word each: with 2 or 3 values expected, CLI11 also
  // took the next word when a 2D image got two ("--spacing 1,1 IMAGE"
  // swallowed IMAGE).
  auto numbers = [](std::vector<double>& out, const char* what) {
    return [&out, what](const std::string& text) {
      // Thrown as CLI11's own error: the parse reports it like any bad option.
      out.clear();
      try {
        for (const std::string& w : split_commas(text)) out.push_back(parse_number(w, what, false));
      } catch (const InputError& e) {
        throw CLI::ValidationError(e.what());
      }
      if (out.size() != 2 && out.size() != 3)
        throw CLI::ValidationError(std::string(what) + ": expected 2 or 3 comma-separated numbers, got '" + text + "'");
    };
  };
  app->add_option_function<std::string>("--spacing", numbers(r.spacing, "--spacing"),
                                         "Voxel spacing sx,sy[,sz] (default: from the image file; 1 for .npy)")
      ->type_name("SX,SY[,SZ]");
  app->add_option_function<std::string>(
         "--origin", numbers(r.origin, "--origin"),
         "Position ox,oy[,oz] of the centre of voxel (0,0,0) (default: from the image file; 0 for .npy)")
      ->type_name("OX,OY[,OZ]");
  app->add_option("--array", r.array, ".vti and legacy .vtk: the point-data array to read (default: the active scalars, else the first (.vtk: the first of one component))");
}

void check_points_output(const std::string& path) {
  const std::string e = extension(path);
  if (e != ".npy" && e != ".ply" && e != ".vtp")
    throw InputError("output " + path + ": points are written as .npy, .ply or .vtp (got '" + e + "')");
  io::check_writable(path);
}

io::ImageReadOptions read_options(const ImageReadArgs& r) {
  io::ImageReadOptions o;
  auto triple = [](const std::vector<double>& v, double third, const char* what) {
    if (v.size() != 2 && v.size() != 3)
      throw InputError(std::string(what) + " takes 2 or 3 numbers, got " + std::to_string(v.size()));
    for (double x : v)
      if (!std::isfinite(x)) throw InputError(std::string(what) + " values must be finite");
    return std::array<double, 3>{v[0], v[1], v.size() == 3 ? v[2] : third};
  };
  if (!r.spacing.empty()) {
    o.spacing = triple(r.spacing, 1.0, "--spacing");
    for (double s : r.spacing)
      if (!(s > 0)) throw InputError("--spacing values must be > 0");
  }
  if (!r.origin.empty()) o.origin = triple(r.origin, 0.0, "--origin");
  o.array = r.array;
  return o;
}

/// --spacing/--origin must have as many values as the image has axes.
void check_read_dims(const ImageReadArgs& r, const ImageGeometry& g, const std::string& path) {
  if (g.dim == 3 && (r.spacing.size() == 2 || r.origin.size() == 2))
    throw InputError(path + ": a 3D image needs 3 values for --spacing / --origin");
  if (g.dim == 2 && (r.spacing.size() == 3 || r.origin.size() == 3))
    throw InputError(path + ": a 2D image takes 2 values for --spacing / --origin, not 3");
}

std::string size_string(const ImageGeometry& g) {
  std::string s = std::to_string(g.size[0]) + "x" + std::to_string(g.size[1]);
  if (g.dim == 3) s += "x" + std::to_string(g.size[2]);
  return s;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The library options from the command-line words (InputError on bad ones).
SampleImageOptions sampler_options(const SamplerArgs& s) {
  SampleImageOptions o;
  o.select = s.select;
  o.schedule = s.schedule == "linear" ? SampleSchedule::linear : SampleSchedule::exponential;
  o.step = s.step;
  o.randomize = !s.no_randomize;
  if (!s.probability.empty()) {
    if (s.probability.size() != 2) throw InputError("--probability takes two numbers lo,hi");
    o.probability_range = {s.probability[0], s.probability[1]};
  }
  o.seed = s.seed;
  if (s.output == "labelled")
    o.output = SampleOutput::labelled;
  else if (s.output == "background")
    o.output = SampleOutput::background;
  else if (s.output == "all")
    o.output = SampleOutput::all;
  else
    throw InputError("--output must be all, labelled or background, got '" + s.output + "'");
  if (!s.background_label.empty()) {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(s.background_label.c_str(), &end, 10);
    if (end != s.background_label.c_str() + s.background_label.size() || errno == ERANGE ||
        v < std::numeric_limits<std::int32_t>::min() || v > std::numeric_limits<std::int32_t>::max())
      throw InputError("--background-label: '" + s.background_label + "' is not a 32-bit integer");
    o.background_label = static_cast<std::int32_t>(v);
  }
  o.joggle = s.joggle;
  o.threads = s.threads;
  // The checks sample_image makes on the options alone, before reading a
  // possibly large image.
  if (o.schedule == SampleSchedule::exponential && o.step < 2)
    throw InputError("--step must be >= 2 for the exponential schedule, got " + std::to_string(o.step));
  if (o.step < 1) throw InputError("--step must be >= 1, got " + std::to_string(o.step));
  const auto [lo, hi] = o.probability_range;
  if (!(lo >= 0 && lo <= hi && hi <= 1)) throw InputError("--probability lo,hi must satisfy 0 <= lo <= hi <= 1");
  if (o.background_label && *o.background_label >= 0)
    throw InputError("--background-label must be < 0 (an outside label), got " + s.background_label);
  if (!(o.joggle >= 0) || !std::isfinite(o.joggle)) throw InputError("--joggle must be a finite number >= 0");
  return o;
}

/// sample_image with the image's path on its errors (the options are
/// already checked, so what is left is about the image and the selection).
LabelledPoints sample_named(const std::string& path, const LabelImage& img, const SampleImageOptions& o) {
  try {
    return sample_image(img, o);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace

bool is_image_path(const std::string& path) {
  const std::string e = extension(path);
  if (e == ".nrrd" || e == ".nhdr" || e == ".mha" || e == ".mhd" || e == ".vti" || e == ".nii" || e == ".hdr")
    return true;
  std::string lower = path.size() >= 7 ? path.substr(path.size() - 7) : path;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower == ".nii.gz";
}

void add_sampler_options(CLI::App* app, SamplerArgs& s) {
  add_read_options(app, s.read);
  app->add_option("--schedule", s.schedule,
                  "Which distances to the nearest boundary keep voxels: exponential (1, N, N^2, ...) or linear "
                  "(1, N, 2N, ...)")
      ->check(CLI::IsMember({"exponential", "linear"}))
      ->capture_default_str();
  app->add_option("--step", s.step, "N of the schedule (>= 2 exponential, >= 1 linear)")->capture_default_str();
  app->add_flag("--no-randomize", s.no_randomize,
                "Keep every voxel the schedule selects (default: keep each with probability 1/distance)");
  app->add_option("--probability", s.probability,
                  "lo,hi: clamp the keep probability 1/distance into [lo, hi] (default 0,1)")
      ->expected(2)
      ->type_name("LO,HI")
      ->delimiter(',')
      ->allow_extra_args(false);
  app->add_option("--seed", s.seed, "Random seed (each voxel's draws depend on seed and voxel index only)")
      ->capture_default_str();
  app->add_option("--background-label", s.background_label,
                  "Give the points of unselected voxels this label (< 0: outside points); default: their own label");
  app->add_option("--joggle", s.joggle,
                  "Move each point randomly by up to F times the smallest spacing (capped at 0.5: points stay in "
                  "their voxel); default 0")
      ->capture_default_str();
}

LabelledPoints sample_image_file(const std::string& image, const SamplerArgs& s) {
  const SampleImageOptions o = sampler_options(s);
  const LabelImage img = io::read_label_image(image, read_options(s.read));
  check_read_dims(s.read, img.geometry, image);
  return sample_named(image, img, o);
}

LabelImage read_label_image_file(const std::string& image, const SamplerArgs& s) {
  (void)sampler_options(s);  // bad options fail before a possibly large read
  LabelImage img = io::read_label_image(image, read_options(s.read));
  check_read_dims(s.read, img.geometry, image);
  return img;
}

LabelledPoints sample_label_image(const std::string& image, const LabelImage& img, const SamplerArgs& s) {
  return sample_named(image, img, sampler_options(s));
}

// ------------------------------------------------------------------ registration

void add_image_commands(CLI::App& app, ImageCommands& c) {
  c.sample_app = app.add_subcommand(
      "sample-image",
      "Sample a label image into labelled points at voxel centres, dense near label boundaries and sparse inside");
  CLI::App* s = c.sample_app;
  s->add_option("IMAGE", c.sample.image,
                image_help("labels, an integer type (a float image is refused: cast it, or `threshold` it)"))
      ->required();
  s->add_option("-o,--output", c.sample.output,
                "Output points with labels: .npy (float64 (N, D); labels in OUT_labels.npy), .ply (binary, double "
                "x y z, int property 'label') or .vtp (VTK vertices, point data 'label')")
      ->required();
  add_sampler_options(s, c.sample.sampler);
  s->add_option("--select", c.sample.sampler.select,
                 "Labels L1,L2,... whose boundaries attract points (default: every label >= 0); a label no voxel "
                 "has is an error")
      ->delimiter(',');
  s->add_option("--threads", c.sample.sampler.threads,
                "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores). Results are identical for any "
                "thread count")
      ->check(NonNegative);
  s->add_option("--output-type", c.sample.sampler.output,
                "Which points: all, labelled (voxels of selected labels) or background (the others); VTK's "
                "OutputType")
      ->check(CLI::IsMember({"all", "labelled", "background"}))
      ->capture_default_str();
  s->add_flag("-q,--quiet", c.sample.quiet, "No summary line");
  s->footer(
      "Distance: 1 on boundary voxels (a face neighbour with another label, one of the two selected), else 1 + the\n"
      "exact city-block distance in voxels to the nearest boundary voxel. Points come in voxel-index order.\n"
      "Examples:\n"
      "  tessera sample-image seg.nrrd -o pts.ply\n"
      "  tessera sample-image labels.npy --spacing 0.5,0.5,1 --select 1,2 --background-label -1 -o pts.npy\n"
      "  tessera sample-image seg.vti --schedule linear --step 4 --no-randomize -o pts.vtp");

  c.probe_app = app.add_subcommand(
      "probe", "Interpolate an image's values at points (bilinear in 2D, trilinear in 3D between voxel centres)");
  CLI::App* p = c.probe_app;
  p->add_option("IMAGE", c.probe.image, image_help("values, any integer or float type"))->required();
  p->add_option("POINTS", c.probe.points,
                "Point file: .npy, .csv/.xyz/.txt (or Qhull's format), .ply, .vtp/.vtu, .vtk (legacy VTK), .pcd, .las or .dump/.lammpstrj (2D images take x,y of 3-column points); - reads standard input")
      ->required();
  p->add_option("-o,--output", c.probe.output,
                ".npy: the values, float64 of shape (N,); .ply/.vtp: the points with a double array 'scalars' "
                "(and 'label' with --labels)")
      ->required();
  add_read_options(p, c.probe.read);
  p->add_option("--labels", c.probe.labels,
                "Per-point integer labels carried to .ply/.vtp output: FILE.npy or a .ply property / .csv column / .vtp, .vtu or .vtk point data array / LAMMPS dump column / .pcd, .las or structured .npy field");
  p->add_option("--outside-value", c.probe.outside_value,
                "Value for points outside the box of voxel centres (a number, nan, inf or -inf)")
      ->capture_default_str();
  p->add_option("--threads", c.probe.threads, "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores)")
      ->check(NonNegative);
  p->add_flag("--keep-non-finite", c.probe.keep_non_finite,
              "Points with a NaN or infinite coordinate (an organized cloud's missing returns) are read and count as "
              "outside (--outside-value) instead of refused");
  p->add_flag("-q,--quiet", c.probe.quiet, "No summary line");
  p->footer(
      "A point is inside when it lies in the box spanned by the voxel centres, far faces included, or\n"
      "within 1e-9 voxel spacings of it (the rounding of (p - origin) / spacing), plus a few ulps of the image's\n"
      "largest coordinate; it then takes the face's value.\n"
      "Examples:\n"
      "  tessera probe field.vti pts.npy -o values.npy\n"
      "  tessera probe density.nrrd pts.ply --outside-value 0 -o probed.ply");
}

int run_image_command(const ImageCommands& c) {
  // No output may replace a file the command reads (io::protect_from_writes).
  if (c.sample_app && c.sample_app->parsed()) io::protect_from_writes(c.sample.image, "the IMAGE");
  if (c.probe_app && c.probe_app->parsed()) {
    io::protect_from_writes(c.probe.image, "the IMAGE");
    io::protect_from_writes(c.probe.points, "the POINTS");
    io::protect_from_writes(c.probe.labels, "--labels");
  }
  if (c.sample_app && c.sample_app->parsed()) return run_sample_image(c.sample);
  if (c.probe_app && c.probe_app->parsed()) return run_probe(c.probe);
  return -1;
}

// ------------------------------------------------------------------ sample-image

int run_sample_image(const SampleImageArgs& a) {
  check_points_output(a.output);
  const auto t0 = std::chrono::steady_clock::now();
  // Read here (not through sample_image_file) to report the image size.
  const SamplerArgs& s = a.sampler;
  const SampleImageOptions o = sampler_options(s);
  const LabelImage img = io::read_label_image(a.image, read_options(s.read));
  check_read_dims(s.read, img.geometry, a.image);
  const LabelledPoints pts = sample_named(a.image, img, o);
  io::WritePointsOptions wo;
  wo.labelled = true;  // every sample is labelled, even when none was drawn
  const auto written = io::write_points(a.output, pts, wo);
  if (!a.quiet) {
    std::printf("tessera sample-image: %zu points (%dD) from %s (%s voxels, %s output) in %.3f s; wrote %s\n",
                pts.size(), pts.dim, a.image.c_str(), size_string(img.geometry).c_str(), s.output.c_str(),
                seconds_since(t0), written_list(written).c_str());
    std::fflush(stdout);
  }
  return kExitOk;
}

// ------------------------------------------------------------------ probe

int run_probe(const ProbeArgs& a) {
  check_points_output(a.output);
  double outside = 0;
  if (!whole_number(a.outside_value, outside))  // nan and inf allowed
    throw InputError("--outside-value: '" + a.outside_value + "' is not a number");
  if (beyond_range(a.outside_value, outside))
    throw InputError("--outside-value: '" + a.outside_value + "' is beyond double's range");
  const auto t0 = std::chrono::steady_clock::now();
  const ScalarImage img = io::read_scalar_image(a.image, read_options(a.read));
  check_read_dims(a.read, img.geometry, a.image);
  io::ReadOptions pro;
  pro.dim = img.geometry.dim;
  pro.labels = a.labels;
  pro.keep_non_finite = a.keep_non_finite;
  pro.non_finite_hint = "--keep-non-finite counts such points as outside";
  const io::PointCloud pc = io::read_points(input_path(a.points), pro);
  ProbeOptions po;
  po.outside_value = outside;
  po.threads = a.threads;
  po.keep_non_finite = a.keep_non_finite;
  ProbeResult r;
  try {
    r = probe(img, pc.coords, po);
  } catch (const InputError& e) {
    throw InputError(a.points + ": " + e.what());
  }
  std::size_t inside = 0;
  for (std::uint8_t v : r.valid) inside += v;

  std::vector<std::string> written;
  if (extension(a.output) == ".npy") {
    io::write_file_atomic(a.output, io::npy_bytes(r.values.data(), {r.values.size()}));
    written.push_back(a.output);
  } else {
    LabelledPoints lp;
    lp.dim = pc.dim;
    lp.coords = pc.coords;
    lp.labels = pc.labels;
    io::WritePointsOptions wo;
    wo.scalars.emplace_back("scalars", std::span<const double>(r.values));
    written = io::write_points(a.output, lp, wo);
  }
  if (!a.quiet) {
    std::printf("tessera probe: %zu points (%zu inside, %zu outside) in %s (%s voxels) in %.3f s; wrote %s\n", pc.n,
                inside, pc.n - inside, a.image.c_str(), size_string(img.geometry).c_str(), seconds_since(t0),
                written_list(written).c_str());
    std::fflush(stdout);
  }
  return kExitOk;
}

}  // namespace tessera::cli
