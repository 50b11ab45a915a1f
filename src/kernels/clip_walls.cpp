// The cells' cuts by walls (kernels/walls.hpp): Hull::clip_wall and
// Tile::clip_wall, compiled here, apart from the clips by neighbours. In the
// kernels' headers their inlined sign pass and exact calls grew the unit the
// engine's instantiations are compiled in, and GCC inlined less into the
// tile's ordinary cut: 2D cells took 2.2% more instructions (stop 88).
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"
#include "tessera/kernels/walls.hpp"

#include <algorithm>
#include <stdexcept>

namespace tessera::kernels {

ClipResult Hull::clip_wall(int k, const walls::Ball<3>& b) {
  const std::size_t nv = verts_.size();
  walls::RelativeWall<3> w;
  if (!walls::may_cut<3>(exact_->walls[k], site_, b, verts_.data(), nv, w)) return ClipResult::unchanged;
  if (sign_.size() < std::max(nv, lanes_.padded())) sign_.resize(std::max(nv, lanes_.padded()));
  const std::size_t removed = walls::signs<3>(verts_.data(), nv, planes_.data(), w, k, *exact_, gen_, sign_);
  if (removed == 0) return ClipResult::unchanged;
  if (removed == nv) {
    resize_vertices(0);
    security2_ = 0;
    return ClipResult::emptied;
  }
  const Index pn = static_cast<Index>(planes_.size());
  if (planes_.size() + 1 >= max_planes) [[unlikely]]
    throw std::length_error("a cell has more than 4294967294 faces (one point with that many neighbours)");
  Plane& pl = planes_.emplace_back();
  for (int a = 0; a < 3; ++a) pl.n[a] = w.n[a];
  pl.d = w.d;
  pl.n1 = w.n1;
  pl.id = wall_plane_id(k);
  pl.scale = 0;
  scaled_planes_ = true;  // the measure computes a wall's foot (front/cell_geometry.hpp)
  if (planes_.size() > cap_) [[unlikely]] grow_table();
  if (hashed_) [[unlikely]] {
    if (blocked_) {  // cut() takes a blocked cell's removed slots from holes_, as its pass lists them
      if (holes_.size() < removed) holes_.resize(removed);
      std::size_t h = 0;
      for (std::size_t t = 0; t < nv; ++t)
        if (sign_[t] < 0) holes_[h++] = static_cast<std::uint32_t>(t);
    }
    cut_huge(pn, nv, removed);
  } else {
    cut<false>(pn, nv, removed);
  }
  return ClipResult::clipped;
}

ClipResult Tile::clip_wall(int k, const walls::Ball<2>& b) {
  const std::size_t nv = verts_.size();
  walls::RelativeWall<2> w;
  if (!walls::may_cut<2>(exact_->walls[k], site_, b, verts_.data(), nv, w)) return ClipResult::unchanged;
  if (sign_.size() < nv) sign_.resize(nv);
  const std::size_t removed = walls::signs<2>(verts_.data(), nv, planes_.data(), w, k, *exact_, gen_, sign_);
  if (removed == 0) return ClipResult::unchanged;
  if (removed == nv) {
    verts_.clear();
    lanes_.clear();
    security2_ = 0;
    return ClipResult::emptied;
  }
  const Index pn = static_cast<Index>(planes_.size());
  Plane& pl = planes_.emplace_back();
  pl.n[0] = w.n[0]; pl.n[1] = w.n[1];
  pl.d = w.d;
  pl.n1 = w.n1;
  pl.id = wall_plane_id(k);
  pl.scale = 0;
  cut(pn, nv, removed);
  return ClipResult::clipped;
}

}  // namespace tessera::kernels
