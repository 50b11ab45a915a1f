// A command on a trajectory's frames: one (--frame INDEX) or a series
// (--frame all, or a slice START:STOP[:STEP]), the command once per frame
// selected, each with its own box where the file's box is the domain, into
// outputs whose names hold {frame}, replaced by the frame's index
// (cells_{frame}.vtu: cells_0.vtu, cells_1.vtu, ..., a series ParaView opens
// as one).
#pragma once

#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "commands.hpp"
#include "tessera/io/atomic_file.hpp"  // check_writable, OutputGroup
#include "stdin_input.hpp"  // shown_path

namespace tessera::cli {

/// One output of a command: its option, as the messages name it, and where
/// its Args keep the path.
template <class Args>
struct SeriesOutput {
  const char* option;
  std::string Args::*path;
};

/// `args` with {frame} in its outputs' names replaced by `index`.
template <class Args>
Args with_frame_names(Args a, std::initializer_list<SeriesOutput<Args>> outputs, std::size_t index) {
  const std::string text = std::to_string(index);
  for (const SeriesOutput<Args>& o : outputs) {
    std::string& path = a.*(o.path);
    for (std::size_t at; (at = path.find("{frame}")) != std::string::npos;) path.replace(at, 7, text);
  }
  return a;
}

/// `run_one(a)`, its outputs renamed into place together once it returns
/// (io::OutputGroup): a failure in any of them leaves every one of the
/// frame's targets as it was (a new cells file beside the old table).
template <class Args, class Run>
int run_committed(const Args& a, Run& run_one) {
  io::OutputGroup outputs;
  const int rc = run_one(a);
  outputs.commit();
  return rc;
}

/// A command's run: `run_one(args)` once, or for each frame of a series.
/// One frame asked for by its INDEX: {frame} in an output's name is its
/// index (from the start, also for -1), as in a series, so that a loop
/// over indices names its files alike; no --frame: the names as given.
/// A series (args.compute.frames): each frame with its place, its box
/// (where the domain is the file's: apply_file_box) and its output names.
/// Every output given must hold {frame} (standard output is refused:
/// several tables in one stream). Each frame's files are whole when
/// written; an error in a frame names it, and the files of the frames
/// before it stay (each frame's are renamed into place together). A frame of no atoms (a dump of a group that was empty
/// then) is skipped with a note on standard error and gets no files; a
/// series of such frames alone is an error. The exit code is the worst of
/// the frames' (a failed --validate goes on to the next frame).
template <class Args, class Run>
int run_frames(const Args& a, std::initializer_list<SeriesOutput<Args>> outputs, Run&& run_one) {
  if (a.compute.frames.empty())
    return run_committed(a.compute.frame.empty() ? a : with_frame_names(a, outputs, a.compute.frame_place.index),
                         run_one);
  for (const SeriesOutput<Args>& o : outputs) {
    const std::string& path = a.*(o.path);
    if (path == "-")
      throw InputError("--frame " + a.compute.frame + " writes one file per frame: " + o.option +
                       " cannot go to standard output; give a file name holding {frame}");
    if (!path.empty() && path.find("{frame}") == std::string::npos)
      throw InputError("--frame " + a.compute.frame + " writes one file per frame: " + o.option +
                       "'s name must hold {frame} (e.g. out_{frame}" + extension(path) + ")");
  }
  // Each frame's arguments are copied from one without the list of frames
  // (a trajectory may have 10^5 of them).
  Args base = a;
  const std::vector<io::FramePlace> frames = std::move(base.compute.frames);
  base.compute.frames.clear();
  // Every frame's outputs are checked before the first frame is computed,
  // as a single run checks its outputs ({frame} may name a folder): each
  // folder, and each name (a FIFO or an input named by a later frame was
  // refused only when that frame was written).
  for (const io::FramePlace& place : frames) {
    if (place.atoms == 0) continue;
    const Args named = with_frame_names(base, outputs, place.index);
    for (const SeriesOutput<Args>& o : outputs)
      if (const std::string& path = named.*(o.path); !path.empty()) io::check_writable(path);
  }
  int rc = kExitOk;
  std::size_t computed = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const io::FramePlace& place = frames[k];
    if (place.atoms == 0) {
      std::fprintf(stderr, "tessera: frame %zu of %s (from line %zu) holds no atoms: skipped, no files for it\n",
                   place.index, shown_path(a.compute.input).c_str(), place.line);
      continue;
    }
    ++computed;
    Args f = base;
    f.compute.frame_place = place;
    f.compute.brief = computed > 1;  // the first frame's summary in full, then a line each
    try {
      if (!a.compute.domain_given) {  // the file's box, where it has one: this frame's own
        f.compute.bounds.clear();
        if (f.compute.periodic_from_file) f.compute.periodic.clear();  // else --periodic's axes
        if (f.compute.tilt_from_file) f.compute.tilt.clear();
        f.compute.box_source.clear();
        apply_file_box(f.compute);
      }
      const int r = run_committed(with_frame_names(f, outputs, place.index), run_one);
      if (r != kExitOk) rc = r;
    } catch (const InputError& e) {
      throw InputError("frame " + std::to_string(place.index) + ": " + e.what() +
                       (computed == 1 ? "" : "; the frames before it were written"));
    }
  }
  if (computed == 0)
    throw InputError("--frame " + a.compute.frame + " selects only frames of no atoms; nothing was written");
  return rc;
}

}  // namespace tessera::cli
