#include "sheardiff/neighbour/neighbour_list.hpp"

#include <algorithm>
#include <cmath>
#include <nanoflann.hpp>
#include <unordered_map>

namespace sheardiff {

namespace {

// Real particles followed by their ghost images, as nanoflann's dataset adaptor; k: the image
// (kx, ky[, kz]) each point is.
template <class D>
struct ImageCloud {
  using Point = typename D::Point;
  using Images = typename D::Images;
  std::vector<Point> pts;
  std::vector<int> owner;
  std::vector<Images> k;

  std::size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(std::size_t idx, std::size_t dim) const { return pts[idx][dim]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
  void add(const Point& x, int who, const Images& image) {
    pts.push_back(x);
    owner.push_back(who);
    k.push_back(image);
  }
};

template <class D>
using Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, ImageCloud<D>>,
                                        ImageCloud<D>, D::space>;

// The shift of image k of the box.
Vec2 shift(const Box& box, const std::array<int, 2>& k) {
  return box.image_shift(k[0], k[1]);
}
Space3 shift(const Box3& box, const std::array<int, 3>& k) {
  return box.image_shift(k[0], k[1], k[2]);
}
void set_image(Pair& pr, const std::array<int, 2>& k) {
  pr.kx = k[0], pr.ky = k[1];
}
void set_image(Pair3& pr, const std::array<int, 3>& k) {
  pr.kx = k[0], pr.ky = k[1], pr.kz = k[2];
}

std::uint64_t pair_key(int i, int j) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
         static_cast<std::uint32_t>(j);
}

}  // namespace

namespace {

// Wrap into the primary cell; a Lees-Edwards crossing in y shifts x by the offset. The images
// crossed are counted, so that the trajectory's position + image . edges is continuous.
template <class D>
void wrap_into_cell(ParticlesOf<D>& p, const BoxOf<D>& box) {
  const std::size_t n = p.size();
  if (p.image.size() != n) p.image.assign(n, typename D::Images{});
  for (std::size_t k = 0; k < n; ++k) {
    auto& x = p.position[k];
    if constexpr (D::space == 3) {
      const double nz = std::floor(x.z() / box.lz);
      x.z() -= nz * box.lz;
      p.image[k][2] += static_cast<int>(nz);
    }
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
// x + (kx Lx + ky le_offset, ky Ly); kx brings it into [0, Lx). Spheres: then z images of all of
// these (periodic z, no offset), so edges and corners are covered.
template <class D>
ImageCloud<D> image_cloud(const ParticlesOf<D>& p, const BoxOf<D>& box, double rc) {
  using Point = typename D::Point;
  using Images = typename D::Images;
  const std::size_t n = p.size();
  ImageCloud<D> cloud;
  cloud.pts.reserve(n + n / 4);
  for (std::size_t k = 0; k < n; ++k) cloud.add(p.position[k], static_cast<int>(k), Images{});
  if (box.lees_edwards) {
    for (std::size_t k = 0; k < n; ++k) {
      const Point& x = p.position[k];
      for (int ky : {1, -1}) {
        if ((ky == 1 && x.y() >= rc) || (ky == -1 && x.y() <= box.ly - rc)) continue;
        Images im{};
        im[0] = -static_cast<int>(std::floor((x.x() + ky * box.le_offset) / box.lx));
        im[1] = ky;
        cloud.add(x + shift(box, im), static_cast<int>(k), im);
      }
    }
  }
  // Images along one periodic axis of everything listed so far.
  const auto periodic = [&](int axis, double length) {
    const std::size_t listed = cloud.pts.size();
    for (std::size_t q = 0; q < listed; ++q) {
      const Point x = cloud.pts[q];
      const int who = cloud.owner[q];
      const Images im = cloud.k[q];
      Point along = Point::Zero();
      along[axis] = length;
      for (int side : {1, -1}) {
        if (side == 1 ? x[axis] >= rc : x[axis] <= length - rc) continue;
        Images moved = im;
        moved[static_cast<std::size_t>(axis)] += side;
        cloud.add(x + side * along, who, moved);
      }
    }
  };
  periodic(0, box.lx);
  if constexpr (D::space == 3) periodic(2, box.lz);
  return cloud;
}

}  // namespace

template <class D>
void NeighbourListOf<D>::rebuild(ParticlesOf<D>& p, const BoxOf<D>& box) {
  const std::size_t n = p.size();
  wrap_into_cell<D>(p, box);
  double amax = 0.0;
  for (double a : p.radius) amax = std::max(amax, a);
  max_cutoff_ = cutoff(amax, amax);
  const double rc = max_cutoff_;
  const ImageCloud<D> cloud = image_cloud<D>(p, box, rc);
  Tree<D> tree(D::space, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  tree.buildIndex();

  std::unordered_map<std::uint64_t, PairHistoryOf<D>> history;
  history.reserve(pairs_.size());
  for (const PairType& pr : pairs_)
    if (pr.history.touching) history.emplace(pair_key(pr.i, pr.j), pr.history);

  pairs_.clear();
  std::vector<std::pair<unsigned int, double>> hits;
  nanoflann::SearchParams params;
  params.sorted = false;
  for (std::size_t a = 0; a < n; ++a) {
    if (p.motion[a] != Motion::Mobile) continue;
    hits.clear();
    double q[D::space];
    for (int c = 0; c < D::space; ++c) q[c] = p.position[a][c];
    tree.radiusSearch(q, rc * rc, hits, params);
    for (const auto& [idx, d2] : hits) {
      const int b = cloud.owner[idx];
      if (b == static_cast<int>(a)) continue;
      const bool b_mobile = p.motion[b] == Motion::Mobile;
      // Each mobile-mobile pair once (i < j); mobile-wall pairs from the mobile side.
      if (b_mobile && b < static_cast<int>(a)) continue;
      const double rcut = cutoff(p.radius[a], p.radius[b]);
      if (d2 > rcut * rcut) continue;
      PairType pr;
      pr.i = static_cast<int>(a);
      pr.j = b;
      set_image(pr, cloud.k[idx]);
      if (auto it = history.find(pair_key(pr.i, pr.j)); it != history.end())
        pr.history = it->second;
      pairs_.push_back(pr);
    }
  }
  // A deterministic order makes runs reproducible and the sparsity pattern well ordered.
  std::sort(pairs_.begin(), pairs_.end(), [](const PairType& x, const PairType& y) {
    return x.i != y.i ? x.i < y.i : x.j < y.j;
  });
  na_since_build_.assign(n, Point::Zero());
  strain_since_build_ = 0.0;
  ++rebuilds_;
}

template <class D>
void NeighbourListOf<D>::advance(const std::vector<Point>& na_displacement, double dstrain) {
  for (std::size_t k = 0; k < na_displacement.size(); ++k) na_since_build_[k] += na_displacement[k];
  strain_since_build_ += std::abs(dstrain);
}

template <class D>
bool NeighbourListOf<D>::needs_rebuild() const {
  double m = 0.0;
  for (const Point& d : na_since_build_) m = std::max(m, d.squaredNorm());
  // Two particles approach by at most twice the largest non-affine displacement plus the
  // affine shear across the largest cut-off distance.
  return 2.0 * std::sqrt(m) + strain_since_build_ * max_cutoff_ > skin_;
}

template class NeighbourListOf<Dim2>;
template class NeighbourListOf<Dim3>;

}  // namespace sheardiff
