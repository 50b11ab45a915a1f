// tessera._core: images (LabelImage, ScalarImage, their readers) and the point
// preparation tools (include/tessera/prep/: sample_image, joggle, fill,
// threshold, probe, lloyd). The tools' outputs are plain arrays: the vectors the
// library returns are moved into numpy arrays (arrays.hpp, adopt), not copied.
// Images keep their buffer in the bound object, which numpy views.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "interrupt.hpp"
#include "options.hpp"
#include "tessera/image.hpp"
#include "tessera/io/image.hpp"
#include "tessera/io/points.hpp"
#include "tessera/labelled_points.hpp"
#include "tessera/prep/fill.hpp"
#include "tessera/prep/joggle.hpp"
#include "tessera/prep/lloyd.hpp"
#include "tessera/prep/probe.hpp"
#include "tessera/prep/sample_image.hpp"
#include "tessera/prep/threshold.hpp"

namespace tessera::python {
namespace {

using Points = py::array_t<double, py::array::c_style>;
using Geometry = std::optional<std::vector<double>>;

// ---- images ---------------------------------------------------------------

/// Spacing / origin overrides (x, y[, z] order, one value per axis, or one
/// value for every axis), then the readers' check of the whole geometry
/// (`what` names the image in its errors): voxel centres past double's
/// range were returned as infinite points.
void apply_geometry(ImageGeometry& g, const Geometry& spacing, const Geometry& origin, const std::string& what) {
  auto set = [&](const Geometry& v, std::array<double, 3>& out, const char* name) {
    if (!v) return;
    if (v->size() == 1) {
      for (int a = 0; a < g.dim; ++a) out[static_cast<std::size_t>(a)] = v->front();
      return;
    }
    if (v->size() != static_cast<std::size_t>(g.dim))
      throw py::value_error(std::string(name) + ": expected " + std::to_string(g.dim) + " values (x, y" +
                            (g.dim == 3 ? ", z" : "") + ") for a " + std::to_string(g.dim) + "D image, got " +
                            std::to_string(v->size()));
    for (int a = 0; a < g.dim; ++a) out[static_cast<std::size_t>(a)] = (*v)[static_cast<std::size_t>(a)];
  };
  set(spacing, g.spacing, "spacing");
  set(origin, g.origin, "origin");
  for (int a = 0; a < g.dim; ++a)
    if (!(g.spacing[static_cast<std::size_t>(a)] > 0))
      throw py::value_error("spacing: must be positive, got " + std::to_string(g.spacing[static_cast<std::size_t>(a)]));
  io::check_image_geometry(what, g);
}

/// Geometry of a C-ordered array of shape (ny, nx) or (nz, ny, nx): x fastest.
ImageGeometry geometry_of(const py::array& a) {
  if (a.ndim() != 2 && a.ndim() != 3) throw py::value_error("image: expected shape (ny, nx) or (nz, ny, nx)");
  if (a.size() == 0) throw py::value_error("image: no voxels");
  ImageGeometry g;
  g.dim = static_cast<int>(a.ndim());
  for (int axis = 0; axis < g.dim; ++axis) g.size[static_cast<std::size_t>(axis)] = a.shape(g.dim - 1 - axis);
  return g;
}

template <class T>
py::array image_view(const ImageGeometry& g, const std::vector<T>& data, py::handle owner) {
  if (data.size() != g.n_voxels()) throw py::value_error("the image's array was taken by release_array()");
  if (g.dim == 2) return view(std::span<const T>(data), {g.size[1], g.size[0]}, owner);
  return view(std::span<const T>(data), {g.size[2], g.size[1], g.size[0]}, owner);
}

py::tuple axes(const std::array<double, 3>& v, int dim) {
  py::tuple t(static_cast<std::size_t>(dim));
  for (int a = 0; a < dim; ++a) t[static_cast<std::size_t>(a)] = v[static_cast<std::size_t>(a)];
  return t;
}

/// The voxel values as a writable array that takes the image's buffer over
/// (the image is left empty): what read_image() returns.
template <class T>
py::array release(ImageGeometry& g, std::vector<T>& data) {
  if (data.size() != g.n_voxels()) throw py::value_error("the image's array was taken by release_array()");
  std::vector<T> taken = std::move(data);
  data.clear();
  if (g.dim == 2) return adopt(std::move(taken), {g.size[1], g.size[0]});
  return adopt(std::move(taken), {g.size[2], g.size[1], g.size[0]});
}

template <class Image>
void def_geometry(py::class_<Image>& cls) {
  cls.def_property_readonly("dim", [](const Image& im) { return im.geometry.dim; })
      .def_property_readonly("shape",
                             [](const Image& im) {
                               const auto& g = im.geometry;
                               return g.dim == 2 ? py::make_tuple(g.size[1], g.size[0])
                                                 : py::make_tuple(g.size[2], g.size[1], g.size[0]);
                             })
      .def_property_readonly("spacing", [](const Image& im) { return axes(im.geometry.spacing, im.geometry.dim); })
      .def_property_readonly("origin", [](const Image& im) { return axes(im.geometry.origin, im.geometry.dim); });
}

// ---- enumerations from their Python names ---------------------------------

JoggleMode joggle_mode(const std::string& s) {
  if (s == "ball") return JoggleMode::ball;
  if (s == "xy") return JoggleMode::xy;
  if (s == "xz") return JoggleMode::xz;
  if (s == "yz") return JoggleMode::yz;
  throw py::value_error("mode: expected 'ball', 'xy', 'xz' or 'yz', got '" + s + "'");
}

SampleSchedule schedule_of(const std::string& s) {
  if (s == "exponential") return SampleSchedule::exponential;
  if (s == "linear") return SampleSchedule::linear;
  throw py::value_error("schedule: expected 'exponential' or 'linear', got '" + s + "'");
}

SampleOutput output_of(const std::string& s) {
  if (s == "all") return SampleOutput::all;
  if (s == "labelled") return SampleOutput::labelled;
  if (s == "background") return SampleOutput::background;
  throw py::value_error("output: expected 'all', 'labelled' or 'background', got '" + s + "'");
}

FillStrategy strategy_of(const std::string& s) {
  if (s == "uniform") return FillStrategy::uniform;
  if (s == "adaptive") return FillStrategy::adaptive;
  throw py::value_error("strategy: expected 'uniform' or 'adaptive', got '" + s + "'");
}

void check_threads(int threads) {
  if (threads < 0) throw py::value_error("threads must be >= 1, or 0/None for the default");
}

/// (points (n, dim), labels (n,) or None), both taking over the library's vectors.
/// (points, labels) of sample_image and fill, whose points always carry
/// labels: none at all is an int32 array of length 0, not None.
py::tuple labelled_points(LabelledPoints&& lp) {
  const auto n = static_cast<py::ssize_t>(lp.size());
  return py::make_tuple(adopt(std::move(lp.coords), {n, static_cast<py::ssize_t>(lp.dim)}),
                        adopt_flat(std::move(lp.labels)));
}

}  // namespace

void bind_prep(py::module_& m) {
  // ---- images ---------------------------------------------------------------
  py::class_<LabelImage> label_image(m, "LabelImage", "An int32 label per voxel, x fastest, with its geometry.");
  def_geometry(label_image);
  label_image.def_property_readonly("array", [](py::object s) {
    const auto& im = s.cast<const LabelImage&>();
    return image_view(im.geometry, im.labels, s);
  });
  label_image.def("release_array", [](LabelImage& im) { return release(im.geometry, im.labels); },
                  "The labels as a writable array that takes the buffer over (the image is left empty).");
  py::class_<ScalarImage> scalar_image(m, "ScalarImage", "A float64 value per voxel, x fastest, with its geometry.");
  def_geometry(scalar_image);
  scalar_image.def_property_readonly("array", [](py::object s) {
    const auto& im = s.cast<const ScalarImage&>();
    return image_view(im.geometry, im.values, s);
  });
  scalar_image.def("release_array", [](ScalarImage& im) { return release(im.geometry, im.values); },
                   "The values as a writable array that takes the buffer over (the image is left empty).");

  m.def(
      "label_image",
      [](const py::array_t<std::int32_t, py::array::c_style>& a, const Geometry& spacing, const Geometry& origin) {
        LabelImage im;
        im.geometry = geometry_of(a);
        apply_geometry(im.geometry, spacing, origin, "image");
        im.labels.assign(a.data(), a.data() + a.size());
        return im;
      },
      py::arg("array").noconvert(), py::arg("spacing").none(true), py::arg("origin").none(true),
      "A LabelImage from a C-ordered int32 array of shape (ny, nx) or (nz, ny, nx) (copied).");
  m.def(
      "scalar_image",
      [](const py::array_t<double, py::array::c_style>& a, const Geometry& spacing, const Geometry& origin) {
        ScalarImage im;
        im.geometry = geometry_of(a);
        apply_geometry(im.geometry, spacing, origin, "image");
        im.values.assign(a.data(), a.data() + a.size());
        return im;
      },
      py::arg("array").noconvert(), py::arg("spacing").none(true), py::arg("origin").none(true),
      "A ScalarImage from a C-ordered float64 array of shape (ny, nx) or (nz, ny, nx) (copied).");
  m.def(
      "read_label_image",
      [](const std::string& path, const Geometry& spacing, const Geometry& origin) {
        LabelImage im = without_gil([&] { return io::read_label_image(path); });
        apply_geometry(im.geometry, spacing, origin, path);
        return im;
      },
      py::arg("path"), py::arg("spacing").none(true), py::arg("origin").none(true),
      "Read an integer image (.npy, .nrrd/.nhdr, .mha/.mhd, .vti); spacing/origin override the file's.");
  m.def(
      "read_scalar_image",
      [](const std::string& path, const Geometry& spacing, const Geometry& origin) {
        ScalarImage im = without_gil([&] { return io::read_scalar_image(path); });
        apply_geometry(im.geometry, spacing, origin, path);
        return im;
      },
      py::arg("path"), py::arg("spacing").none(true), py::arg("origin").none(true),
      "Read any numeric image as float64; spacing/origin override the file's.");

  // ---- sampler --------------------------------------------------------------
  m.def(
      "sample_image",
      [](const LabelImage& image, const std::vector<std::int32_t>& select, const std::string& schedule, int step,
         bool randomize, std::array<double, 2> probability_range, std::uint64_t seed, const std::string& output,
         std::optional<std::int32_t> background_label, double joggle, int threads) {
        check_threads(threads);
        SampleImageOptions opt;
        opt.select = select;
        opt.schedule = schedule_of(schedule);
        opt.step = step;
        opt.randomize = randomize;
        opt.probability_range = probability_range;
        opt.seed = seed;
        opt.output = output_of(output);
        opt.background_label = background_label;
        opt.joggle = joggle;
        opt.threads = threads;
        opt.progress = interrupt_check();
        return labelled_points(without_gil([&] { return sample_image(image, opt); }));
      },
      py::arg("image"), py::arg("select"), py::arg("schedule"), py::arg("step"), py::arg("randomize"),
      py::arg("probability_range"), py::arg("seed"), py::arg("output"), py::arg("background_label").none(true),
      py::arg("joggle"), py::arg("threads"), "Points sampled near the label boundaries: (points, labels).");

  m.def(
      "boundary_distance",
      [](const LabelImage& image, const std::vector<std::int32_t>& select) {
        auto d = without_gil([&] { return boundary_distance(image, select); });
        const auto& g = image.geometry;
        return g.dim == 2 ? adopt(std::move(d), {g.size[1], g.size[0]})
                          : adopt(std::move(d), {g.size[2], g.size[1], g.size[0]});
      },
      py::arg("image"), py::arg("select"), "The sampler's per-voxel boundary distance (int32, the image's shape).");

  // ---- joggle -----------------------------------------------------------------
  m.def(
      "joggle",
      [](const Points& points, double radius, bool absolute, const std::string& mode, const py::object& mask,
         std::uint64_t seed, int threads, bool keep_non_finite) {
        const int dim = checked_dim(points);
        check_threads(threads);
        JoggleOptions opt;
        opt.keep_non_finite = keep_non_finite;
        opt.radius = radius;
        opt.absolute = absolute;
        opt.mode = joggle_mode(mode);
        opt.seed = seed;
        opt.threads = threads;
        opt.progress = interrupt_check();
        std::span<const std::uint8_t> mask_span;
        if (!mask.is_none()) {
          if (!py::isinstance<py::array_t<std::uint8_t, py::array::c_style>>(mask))
            throw py::type_error("mask must be None or a C-contiguous uint8 array");
          auto a = mask.cast<py::array_t<std::uint8_t, py::array::c_style>>();
          if (a.ndim() != 1) throw py::value_error("mask must be one-dimensional");
          mask_span = {a.data(), static_cast<std::size_t>(a.size())};
        }
        const auto pts = as_span(points);
        auto out = without_gil([&] { return tessera::joggle(pts, dim, opt, mask_span); });
        return adopt(std::move(out), {points.shape(0), dim});
      },
      py::arg("points").noconvert(), py::arg("radius"), py::arg("absolute"), py::arg("mode"),
      py::arg("mask").none(true), py::arg("seed"), py::arg("threads"), py::arg("keep_non_finite"),
      "A joggled copy of the points.");

  // ---- fill -------------------------------------------------------------------
  m.def(
      "fill",
      [](const Points& points, const py::object& labels, const std::string& strategy, std::int32_t background_label,
         std::int32_t in_label, double points_per_bin, const std::optional<std::vector<double>>& bounds,
         double joggle, std::uint64_t seed, int threads, bool keep_non_finite) {
        const int dim = checked_dim(points);
        check_threads(threads);
        FillOptions opt;
        opt.keep_non_finite = keep_non_finite;
        opt.strategy = strategy_of(strategy);
        opt.background_label = background_label;
        opt.in_label = in_label;
        opt.points_per_bin = points_per_bin;
        if (bounds) opt.bounds = bounds_from(*bounds, dim);
        opt.joggle = joggle;
        opt.seed = seed;
        opt.threads = threads;
        opt.progress = interrupt_check();
        const auto pts = as_span(points);
        const auto lab = as_labels(labels);
        return labelled_points(without_gil([&] { return tessera::fill(pts, dim, lab, opt); }));
      },
      py::arg("points").noconvert(), py::arg("labels").none(true), py::arg("strategy"), py::arg("background_label"),
      py::arg("in_label"), py::arg("points_per_bin"), py::arg("bounds").none(true), py::arg("joggle"),
      py::arg("seed"), py::arg("threads"), py::arg("keep_non_finite"),
      "The points followed by background points in empty bins: (points, labels).");

  // ---- lloyd ------------------------------------------------------------------
  m.def(
      "lloyd",
      [](const Points& points, const py::object& labels, const std::optional<std::vector<double>>& bounds,
         double padding, bool ignore_outside, int threads, const std::string& method,
         const std::array<bool, 3>& periodic, const std::array<double, 3>& tilt, const py::object& radii,
         int iterations, double tolerance, const py::object& walls) {
        const int dim = checked_dim(points);
        LloydOptions opt;
        fill_common(opt.voronoi, dim, bounds, padding, ignore_outside, threads);
        opt.voronoi.walls = walls_from(walls, dim);
        opt.voronoi.periodic = periodic;
        opt.voronoi.tilt = tilt;
        opt.voronoi.radii = as_radii(radii);  // views the caller's array, alive through the call
        if (method == "auto") opt.voronoi.cell_method = CellMethod::automatic;
        else if (method == "search") opt.voronoi.cell_method = CellMethod::search;
        else if (method == "insertion") opt.voronoi.cell_method = CellMethod::insertion;
        else throw py::value_error("method: expected 'auto', 'search' or 'insertion', got '" + method + "'");
        opt.iterations = iterations;
        opt.tolerance = tolerance;
        const auto pts = as_span(points);
        const auto lab = as_labels(labels);
        LloydResult r = without_gil([&] { return tessera::lloyd(pts, dim, lab, opt); });
        std::vector<std::int64_t> moved(r.moved.begin(), r.moved.end());
        const py::object domain = r.domain ? py::object(bounds_tuple(*r.domain, dim)) : py::none();
        return py::make_tuple(adopt(std::move(r.points), {points.shape(0), dim}), r.iterations,
                              adopt_flat(std::move(r.largest_displacement)), adopt_flat(std::move(r.rms_displacement)),
                              adopt_flat(std::move(moved)), domain, r.spacing, r.threads_used);
      },
      py::arg("points").noconvert(), py::arg("labels").none(true), py::arg("bounds").none(true), py::arg("padding"),
      py::arg("ignore_outside"), py::arg("threads"), py::arg("method"), py::arg("periodic"), py::arg("tilt"),
      py::arg("radii").none(true), py::arg("iterations"), py::arg("tolerance"), py::arg("walls").none(true) = py::none(),
      "Lloyd relaxation: (points (n, dim), iterations done, largest and rms displacement per iteration, points "
      "moved per iteration, domain or None, spacing, threads used). Runs without the GIL.");

  // ---- read_points -----------------------------------------------------------
  m.def(
      "read_points",
      [](const std::string& path, int dim, const std::string& labels, bool keep_non_finite, std::int64_t frame) {
        io::ReadOptions opt;
        opt.dim = dim;
        opt.labels = labels;
        opt.keep_non_finite = keep_non_finite;
        opt.non_finite_hint = "keep_non_finite=True keeps such points";
        io::PointCloud pc = without_gil([&] {
          if (frame != 0) opt.frame = io::find_frame(path, frame);
          return io::read_points(path, opt);
        });
        const auto n = static_cast<py::ssize_t>(pc.n);
        py::object lab = py::none();
        if (!labels.empty()) lab = adopt_flat(std::move(pc.labels));
        return py::make_tuple(adopt(std::move(pc.coords), {n, static_cast<py::ssize_t>(pc.dim)}), lab);
      },
      py::arg("path"), py::arg("dim"), py::arg("labels"), py::arg("keep_non_finite"), py::arg("frame"),
      "A point file as the command line reads it: (points (n, dim), labels (n,) or None); a trajectory's frame "
      "(0 the first, negative from the end).");

  // ---- read_scalars -----------------------------------------------------------
  m.def(
      "read_scalars",
      [](const std::string& path, const std::string& name, std::int64_t frame) {
        std::vector<double> v = without_gil([&] {
          io::FramePlace at;
          if (frame != 0) at = io::find_frame(path, frame);
          return io::read_point_scalars(path, name, at);
        });
        return adopt_flat(std::move(v));
      },
      py::arg("path"), py::arg("name"), py::arg("frame"),
      "One number per point, as the command line's --radii NAME or threshold --scalars NAME read them: a .npy "
      "file, or a named column, property, point data array or field of the point file (a trajectory's frame).");

  // ---- read_frame -------------------------------------------------------------
  m.def(
      "read_frame",
      [](const std::string& path, std::uint64_t offset, std::size_t line, int dim, const std::string& labels) {
        io::ReadOptions opt;
        opt.dim = dim;
        opt.labels = labels;
        io::TrajectoryFrame f = without_gil([&] { return io::read_frame(path, offset, line, opt); });
        const auto n = static_cast<py::ssize_t>(f.points.n);
        py::object lab = py::none(), box = py::none(), step = py::none();
        if (!labels.empty()) lab = adopt_flat(std::move(f.points.labels));
        if (f.box) {
          box = py::make_tuple(f.box->lo, f.box->hi, f.box->tilt, f.box->periodic, f.box->timestep);
          if (f.box->declared_by.rfind("LAMMPS", 0) == 0) step = py::int_(f.box->timestep);
        }
        return py::make_tuple(adopt(std::move(f.points.coords), {n, static_cast<py::ssize_t>(f.points.dim)}), lab, box,
                              step, f.next_offset, f.next_line, f.last);
      },
      py::arg("path"), py::arg("offset"), py::arg("line"), py::arg("dim"), py::arg("labels"),
      "The trajectory frame at a byte offset: (points, labels or None, box or None, timestep or None, next_offset, "
      "next_line, last).");

  // ---- find_frames ------------------------------------------------------------
  m.def(
      "find_frames",
      [](const std::string& path) {
        const std::vector<io::FramePlace> places = without_gil([&] { return io::find_frames(path); });
        py::list out;
        for (const io::FramePlace& p : places) out.append(py::make_tuple(p.offset, p.line));
        return out;
      },
      py::arg("path"), "Where each frame of a trajectory starts: [(offset, line), ...], in file order.");

  // ---- read_box ---------------------------------------------------------------
  m.def(
      "read_box",
      [](const std::string& path, std::int64_t frame) -> py::object {
        const std::optional<io::FileBox> b = without_gil(
            [&] { return io::read_file_box(path, frame == 0 ? io::FramePlace{} : io::find_frame(path, frame)); });
        if (!b) return py::none();
        return py::make_tuple(b->lo, b->hi, b->tilt, b->periodic, b->timestep);
      },
      py::arg("path"), py::arg("frame"),
      "The box a point file declares in a frame (0 the first, negative from the end): (lo, hi, tilt, periodic, "
      "timestep), or None.");

  // ---- threshold --------------------------------------------------------------
  m.def(
      "threshold",
      [](const py::array_t<double, py::array::c_style>& scalars,
         const std::vector<std::tuple<double, double, std::int32_t>>& intervals, std::int32_t background_label) {
        if (scalars.ndim() != 1) throw py::value_error("scalars must be one-dimensional");
        ThresholdOptions opt;
        for (const auto& [lo, hi, label] : intervals) opt.intervals.push_back({lo, hi, label});
        opt.background_label = background_label;
        const std::span<const double> s(scalars.data(), static_cast<std::size_t>(scalars.size()));
        return adopt_flat(without_gil([&] { return tessera::threshold(s, opt); }));
      },
      py::arg("scalars").noconvert(), py::arg("intervals"), py::arg("background_label"),
      "Labels by half-open intervals [lo, hi); background_label elsewhere and for NaN.");

  // ---- probe ------------------------------------------------------------------
  m.def(
      "probe",
      [](const ScalarImage& image, const Points& points, double outside_value, int threads, bool keep_non_finite) {
        if (checked_dim(points) != image.geometry.dim)
          throw py::value_error("points: " + std::to_string(points.shape(1)) + "D points for a " +
                                std::to_string(image.geometry.dim) + "D image");
        check_threads(threads);
        ProbeOptions opt;
        opt.outside_value = outside_value;
        opt.threads = threads;
        opt.keep_non_finite = keep_non_finite;
        opt.progress = interrupt_check();
        const auto pts = as_span(points);
        ProbeResult r = without_gil([&] { return tessera::probe(image, pts, opt); });
        return py::make_tuple(adopt_flat(std::move(r.values)), adopt_flat(std::move(r.valid)));
      },
      py::arg("image"), py::arg("points").noconvert(), py::arg("outside_value"), py::arg("threads"),
      py::arg("keep_non_finite"),
      "Linear interpolation of the image at the points: (values float64, valid uint8).");
}

}  // namespace tessera::python
