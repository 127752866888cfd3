#include "lab/core/flat_joint.hpp"

#include <stdexcept>

namespace rocklab {

FaceLayout FaceLayout::of2D(int pieces) {
  if (pieces < 1) throw std::invalid_argument("a flat joint needs at least one element");
  FaceLayout L;
  L.dimension = 2;
  L.radial = pieces;
  const double l = 2.0 / pieces;  // the face spans [-1, 1]
  for (int k = 0; k < pieces; ++k) {
    FaceElementShape s;
    s.area = l;
    s.x = -1.0 + (k + 0.5) * l;
    s.ixx = l * l * l / 12.0;
    L.elements.push_back(s);
  }
  return L;
}

FaceLayout FaceLayout::of3D(int rings, int sectors) {
  if (rings < 1 || sectors < 1)
    throw std::invalid_argument("a flat joint needs at least one element");
  FaceLayout L;
  L.dimension = 3;
  L.radial = rings;
  L.circumferential = sectors;
  const double da = 2.0 * std::numbers::pi / sectors;
  for (int i = 0; i < rings; ++i) {
    const double ra = static_cast<double>(i) / rings, rb = static_cast<double>(i + 1) / rings;
    const double r2 = rb * rb - ra * ra, r3 = (rb * rb * rb - ra * ra * ra) / 3.0;
    const double r4 = (rb * rb * rb * rb - ra * ra * ra * ra) / 4.0;
    for (int k = 0; k < sectors; ++k) {
      const double a = k * da, b = (k + 1) * da;
      FaceElementShape s;
      s.area = 0.5 * da * r2;
      // First and second moments of the annular sector about the face's centre, in polar
      // coordinates (x = r cos t, y = r sin t, dA = r dr dt), then moved to its centroid.
      s.x = r3 * (std::sin(b) - std::sin(a)) / s.area;
      s.y = r3 * (std::cos(a) - std::cos(b)) / s.area;
      const double xx = r4 * (0.5 * (b - a) + 0.25 * (std::sin(2 * b) - std::sin(2 * a)));
      const double yy = r4 * (0.5 * (b - a) - 0.25 * (std::sin(2 * b) - std::sin(2 * a)));
      const double xy = r4 * 0.5 * (std::sin(b) * std::sin(b) - std::sin(a) * std::sin(a));
      s.ixx = xx - s.area * s.x * s.x;
      s.iyy = yy - s.area * s.y * s.y;
      s.ixy = xy - s.area * s.x * s.y;
      L.elements.push_back(s);
    }
  }
  return L;
}

std::size_t FaceLayout::mirror(std::size_t e) const {
  if (dimension == 2) return elements.size() - 1 - e;  // the face's direction reverses
  const std::size_t ring = e / circumferential, k = e % circumferential;
  return ring * circumferential + (circumferential - 1 - k);  // 3D: angle t -> -t
}

template <int D>
void FaceState<D>::swapSides(const FaceLayout& layout) {
  std::vector<FaceElement<D>> out(elements.size());
  for (std::size_t e = 0; e < elements.size(); ++e) {
    out[e] = elements[layout.mirror(e)];
    // On the other particle every force and moment is opposite: in its frame a component
    // along an axis that turns over keeps its sign, and the twist about n too.
    if (layout.dimension == 3) {
      out[e].fs[0] = -out[e].fs[0];
      out[e].bend[0] = -out[e].bend[0];
    } else {
      out[e].bend[0] = -out[e].bend[0];
    }
  }
  elements.swap(out);
}

template struct FaceState<2>;
template struct FaceState<3>;

}  // namespace rocklab
