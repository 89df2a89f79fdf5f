#include "sheardiff/neighbour/neighbour_list.hpp"

#include <algorithm>
#include <cmath>
#include <nanoflann.hpp>
#include <unordered_map>

namespace sheardiff {

namespace {

// Real particles followed by their ghost images, as nanoflann's dataset adaptor.
struct ImageCloud {
  std::vector<Vec2> pts;
  std::vector<int> owner;
  std::vector<int> kx, ky;

  std::size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(std::size_t idx, std::size_t dim) const { return pts[idx][dim]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
  void add(const Vec2& x, int who, int ix, int iy) {
    pts.push_back(x);
    owner.push_back(who);
    kx.push_back(ix);
    ky.push_back(iy);
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, ImageCloud>,
                                                 ImageCloud, 2>;

std::uint64_t pair_key(int i, int j) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
         static_cast<std::uint32_t>(j);
}

}  // namespace

namespace {

// Wrap into the primary cell; a Lees-Edwards crossing in y shifts x by the offset. The images
// crossed are counted, so that the trajectory's position + image . edges is continuous.
void wrap_into_cell(Particles& p, const Box& box) {
  const std::size_t n = p.size();
  if (p.image.size() != n) p.image.assign(n, {0, 0});
  for (std::size_t k = 0; k < n; ++k) {
    Vec2& x = p.position[k];
    double ny = 0.0;
    if (box.lees_edwards) {
      ny = std::floor(x.y() / box.ly);
      x.y() -= ny * box.ly;
      x.x() -= ny * box.le_offset;
    }
    const double nx = std::floor(x.x() / box.lx);
    x.x() -= nx * box.lx;
    p.image[k][0] += static_cast<int>(nx);
    p.image[k][1] += static_cast<int>(ny);
  }
}

// The particles and every periodic image within rc of the cell: y images first (Lees-Edwards),
// then x images of everything, so corners are covered. Image (kx, ky) of x sits at
// x + (kx Lx + ky le_offset, ky Ly); kx brings it into [0, Lx).
ImageCloud image_cloud(const Particles& p, const Box& box, double rc) {
  const std::size_t n = p.size();
  ImageCloud cloud;
  cloud.pts.reserve(n + n / 4);
  for (std::size_t k = 0; k < n; ++k) cloud.add(p.position[k], static_cast<int>(k), 0, 0);
  if (box.lees_edwards) {
    for (std::size_t k = 0; k < n; ++k) {
      const Vec2& x = p.position[k];
      for (int ky : {1, -1}) {
        if ((ky == 1 && x.y() >= rc) || (ky == -1 && x.y() <= box.ly - rc)) continue;
        const int kx = -static_cast<int>(std::floor((x.x() + ky * box.le_offset) / box.lx));
        cloud.add(x + box.image_shift(kx, ky), static_cast<int>(k), kx, ky);
      }
    }
  }
  const std::size_t with_y = cloud.pts.size();
  for (std::size_t q = 0; q < with_y; ++q) {
    const Vec2 x = cloud.pts[q];
    const int who = cloud.owner[q], kx = cloud.kx[q], ky = cloud.ky[q];
    if (x.x() < rc) cloud.add(x + Vec2(box.lx, 0.0), who, kx + 1, ky);
    if (x.x() > box.lx - rc) cloud.add(x - Vec2(box.lx, 0.0), who, kx - 1, ky);
  }
  return cloud;
}

}  // namespace

void NeighbourList::rebuild(Particles& p, const Box& box) {
  const std::size_t n = p.size();
  wrap_into_cell(p, box);
  double amax = 0.0;
  for (double a : p.radius) amax = std::max(amax, a);
  max_cutoff_ = cutoff(amax, amax);
  const double rc = max_cutoff_;
  const ImageCloud cloud = image_cloud(p, box, rc);
  Tree tree(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  tree.buildIndex();

  std::unordered_map<std::uint64_t, PairHistory> history;
  history.reserve(pairs_.size());
  for (const Pair& pr : pairs_)
    if (pr.history.touching) history.emplace(pair_key(pr.i, pr.j), pr.history);

  pairs_.clear();
  std::vector<std::pair<unsigned int, double>> hits;
  nanoflann::SearchParams params;
  params.sorted = false;
  for (std::size_t a = 0; a < n; ++a) {
    if (p.motion[a] != Motion::Mobile) continue;
    hits.clear();
    const double q[2] = {p.position[a].x(), p.position[a].y()};
    tree.radiusSearch(q, rc * rc, hits, params);
    for (const auto& [idx, d2] : hits) {
      const int b = cloud.owner[idx];
      if (b == static_cast<int>(a)) continue;
      const bool b_mobile = p.motion[b] == Motion::Mobile;
      // Each mobile-mobile pair once (i < j); mobile-wall pairs from the mobile side.
      if (b_mobile && b < static_cast<int>(a)) continue;
      const double rcut = cutoff(p.radius[a], p.radius[b]);
      if (d2 > rcut * rcut) continue;
      Pair pr;
      pr.i = static_cast<int>(a);
      pr.j = b;
      pr.kx = cloud.kx[idx];
      pr.ky = cloud.ky[idx];
      if (auto it = history.find(pair_key(pr.i, pr.j)); it != history.end())
        pr.history = it->second;
      pairs_.push_back(pr);
    }
  }
  // A deterministic order makes runs reproducible and the sparsity pattern well ordered.
  std::sort(pairs_.begin(), pairs_.end(),
            [](const Pair& x, const Pair& y) { return x.i != y.i ? x.i < y.i : x.j < y.j; });
  na_since_build_.assign(n, Vec2::Zero());
  strain_since_build_ = 0.0;
  ++rebuilds_;
}

void NeighbourList::advance(const std::vector<Vec2>& na_displacement, double dstrain) {
  for (std::size_t k = 0; k < na_displacement.size(); ++k) na_since_build_[k] += na_displacement[k];
  strain_since_build_ += std::abs(dstrain);
}

bool NeighbourList::needs_rebuild() const {
  double m = 0.0;
  for (const Vec2& d : na_since_build_) m = std::max(m, d.squaredNorm());
  // Two particles approach by at most twice the largest non-affine displacement plus the
  // affine shear across the largest cut-off distance.
  return 2.0 * std::sqrt(m) + strain_since_build_ * max_cutoff_ > skin_;
}

}  // namespace sheardiff
