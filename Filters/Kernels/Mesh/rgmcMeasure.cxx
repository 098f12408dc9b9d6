// The volume box's frames and the caps that close a surface cut by the volume's border.
#include "rgmcMeasure.h"

#include <algorithm>
#include <map>
#include <tuple>

namespace rgmc
{

void VolumeBox::ToIndex(const double world[3], double index[3]) const
{
  const double d[3] = { world[0] - this->Origin[0], world[1] - this->Origin[1],
    world[2] - this->Origin[2] };
  for (int c = 0; c < 3; ++c)
  {
    // Direction is orthonormal: its inverse is its transpose.
    const double along =
      this->Direction[c] * d[0] + this->Direction[3 + c] * d[1] + this->Direction[6 + c] * d[2];
    index[c] = along / this->Spacing[c];
  }
}

void VolumeBox::ToWorld(const double index[3], double world[3]) const
{
  for (int r = 0; r < 3; ++r)
  {
    world[r] = this->Origin[r];
    for (int c = 0; c < 3; ++c)
    {
      world[r] += this->Direction[3 * r + c] * this->Spacing[c] * index[c];
    }
  }
}

double VolumeBox::Handedness() const
{
  const double* d = this->Direction;
  const double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
    d[2] * (d[3] * d[7] - d[4] * d[6]);
  return det < 0 ? -1.0 : 1.0;
}

void VolumeBox::Frame(double centre[3], double& scale) const
{
  double middle[3], diagonal = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    middle[a] = 0.5 * (this->Extent[2 * a] + this->Extent[2 * a + 1]);
    const double side = (this->Extent[2 * a + 1] - this->Extent[2 * a]) * this->Spacing[a];
    diagonal += side * side;
  }
  this->ToWorld(middle, centre);
  diagonal = std::sqrt(diagonal);
  scale = 1.0;
  while (scale < diagonal)
  {
    scale *= 2.0;
  }
  while (scale >= 2.0 * diagonal && diagonal > 0.0)
  {
    scale *= 0.5;
  }
}

void BorderEdge::Pack(double* out) const
{
  out[0] = static_cast<double>(this->From);
  out[1] = static_cast<double>(this->To);
  out[2] = this->FromFaces;
  out[3] = this->ToFaces;
  std::copy_n(this->FromIndex, 3, out + 4);
  std::copy_n(this->ToIndex, 3, out + 7);
}

BorderEdge BorderEdge::Unpack(const double* in)
{
  BorderEdge e;
  e.From = static_cast<std::int64_t>(in[0]);
  e.To = static_cast<std::int64_t>(in[1]);
  e.FromFaces = static_cast<int>(in[2]);
  e.ToFaces = static_cast<int>(in[3]);
  std::copy_n(in + 4, 3, e.FromIndex);
  std::copy_n(in + 7, 3, e.ToIndex);
  return e;
}

namespace
{

/// One face of the box as a rectangle [U0, U1] x [V0, V1] in index coordinates (U, V) such that
/// U x V is the face's outward normal: its sides, counterclockwise from (U0, V0), are walked by
/// a parameter t in [0, perimeter).
struct Face
{
  int Bit;  // the face's bit in BorderEdge's face masks
  int U, V; // the index axes of the rectangle's coordinates
  double U0, U1, V0, V1;
  int SideBits[4]; // the faces along sides v = V0, u = U1, v = V1, u = U0

  Face(int face, const VolumeBox& box)
  {
    const int axis = face / 2, high = face % 2;
    this->Bit = 1 << face;
    this->U = high ? (axis + 1) % 3 : (axis + 2) % 3;
    this->V = high ? (axis + 2) % 3 : (axis + 1) % 3;
    this->U0 = box.Extent[2 * this->U];
    this->U1 = box.Extent[2 * this->U + 1];
    this->V0 = box.Extent[2 * this->V];
    this->V1 = box.Extent[2 * this->V + 1];
    this->SideBits[0] = 1 << (2 * this->V);
    this->SideBits[1] = 1 << (2 * this->U + 1);
    this->SideBits[2] = 1 << (2 * this->V + 1);
    this->SideBits[3] = 1 << (2 * this->U);
  }
  double Width() const { return this->U1 - this->U0; }
  double Height() const { return this->V1 - this->V0; }
  double Perimeter() const { return 2.0 * (this->Width() + this->Height()); }
  /// Where the side `side` starts.
  double SideStart(int side) const
  {
    const double starts[4] = { 0.0, this->Width(), this->Width() + this->Height(),
      2.0 * this->Width() + this->Height() };
    return starts[side];
  }
  /// The rectangle's corner at the start of side `side`.
  void Corner(int side, double uv[2]) const
  {
    uv[0] = side == 0 || side == 3 ? this->U0 : this->U1;
    uv[1] = side == 0 || side == 1 ? this->V0 : this->V1;
  }
  /// The parameter of a point on side `side`.
  double At(int side, const double uv[2]) const
  {
    const double along[4] = { uv[0] - this->U0, uv[1] - this->V0, this->U1 - uv[0],
      this->V1 - uv[1] };
    const double length = side % 2 ? this->Height() : this->Width();
    return this->SideStart(side) + std::min(std::max(along[side], 0.0), length);
  }
  /// Twice the signed area of the triangle (U0, V0), a, b.
  double Cross(const double a[2], const double b[2]) const
  {
    return (a[0] - this->U0) * (b[1] - this->V0) - (a[1] - this->V0) * (b[0] - this->U0);
  }
};

/// A place where the cap's outline meets the face's sides: it arrives there from the face's
/// inside and goes on along the sides (Arrival), or leaves the sides into the face.
struct Event
{
  double Along; // where on the face's perimeter (Face::At)
  int Kind;     // -1 arrival, +1 departure
  std::int64_t Gid;
  double UV[2];
  bool operator<(const Event& o) const
  {
    return std::tie(this->Along, this->Kind, this->Gid) < std::tie(o.Along, o.Kind, o.Gid);
  }
};

struct FaceCap
{
  bool HasEvents = false;
  double TwiceLoopArea = 0.0;                     // the mesh's edges alone
  double TwiceArea = 0.0;                         // the cap, when HasEvents
  std::vector<std::pair<double, double>> Covered; // the sides' stretches in the cap (t, t')
};

bool CoveredAt(const FaceCap& cap, double t, double perimeter)
{
  for (const auto& stretch : cap.Covered)
  {
    const double end = stretch.second < stretch.first ? stretch.second + perimeter : stretch.second;
    if ((t >= stretch.first && t <= end) ||
      (t + perimeter >= stretch.first && t + perimeter <= end))
    {
      return true;
    }
  }
  return false;
}

/// The mesh's boundary edges among `edges` (sorted in place): those no other triangle has.
std::vector<BorderEdge> BoundaryEdges(std::vector<BorderEdge>& edges)
{
  auto key = [](const BorderEdge& e)
  { return std::make_tuple(std::min(e.From, e.To), std::max(e.From, e.To), e.From); };
  std::sort(edges.begin(), edges.end(),
    [&key](const BorderEdge& a, const BorderEdge& b) { return key(a) < key(b); });
  std::vector<BorderEdge> boundary;
  for (std::size_t i = 0; i < edges.size();)
  {
    std::size_t j = i + 1;
    while (j < edges.size() &&
      std::min(edges[j].From, edges[j].To) == std::min(edges[i].From, edges[i].To) &&
      std::max(edges[j].From, edges[j].To) == std::max(edges[i].From, edges[i].To))
    {
      ++j;
    }
    if (j == i + 1)
    {
      boundary.push_back(edges[i]);
    }
    i = j;
  }
  return boundary;
}

/// Where the outline of the cap on `face` meets the face's sides: the ends of the boundary
/// edges' chains in the face, arrivals and departures, unsorted. Adds the edges' own loop area
/// to `cap`; an outline that ends inside the face opens `caps`.
std::vector<Event> OutlineEvents(
  const std::vector<BorderEdge>& boundary, const Face& face, FaceCap& cap, Caps& caps)
{
  // The cap's outline runs the mesh's boundary edges backwards.
  std::map<std::int64_t, std::pair<int, const BorderEdge*>> net; // gid: out - in
  for (const BorderEdge& e : boundary)
  {
    if (!(e.FromFaces & e.ToFaces & face.Bit))
    {
      continue;
    }
    const double p[2] = { e.ToIndex[face.U], e.ToIndex[face.V] };
    const double q[2] = { e.FromIndex[face.U], e.FromIndex[face.V] };
    cap.TwiceLoopArea += face.Cross(p, q);
    auto& out = net[e.To];
    out.first += 1;
    out.second = &e;
    auto& in = net[e.From];
    in.first -= 1;
    in.second = &e;
  }
  std::vector<Event> events;
  for (const auto& entry : net)
  {
    if (entry.second.first == 0)
    {
      continue;
    }
    const BorderEdge& e = *entry.second.second;
    const bool to = e.To == entry.first;
    const int faceBits = to ? e.ToFaces : e.FromFaces;
    const double* x = to ? e.ToIndex : e.FromIndex;
    const double uv[2] = { x[face.U], x[face.V] };
    int side = 0;
    while (side < 4 && !(faceBits & face.SideBits[side]))
    {
      ++side;
    }
    if (side == 4)
    {
      caps.Closed = false; // an outline that ends inside the face: the surface has a hole
      continue;
    }
    const int kind = entry.second.first > 0 ? 1 : -1;
    for (int n = 0; n < std::abs(entry.second.first); ++n)
    {
      events.push_back(Event{ face.At(side, uv), kind, entry.first, { uv[0], uv[1] } });
    }
  }
  return events;
}

/// Closes the cap on `face` along its sides, from each arrival to the departure after it
/// (counterclockwise, through the corners between): its area and the stretches it covers.
/// An arrival not followed by a departure opens `caps`.
void CloseAlongSides(std::vector<Event>& events, const Face& face, FaceCap& cap, Caps& caps)
{
  cap.HasEvents = true;
  std::sort(events.begin(), events.end());
  double twice = cap.TwiceLoopArea;
  const double perimeter = face.Perimeter();
  for (std::size_t i = 0; i < events.size(); ++i)
  {
    if (events[i].Kind != -1)
    {
      continue;
    }
    const Event& from = events[i];
    const Event& to = events[(i + 1) % events.size()];
    if (to.Kind != 1)
    {
      caps.Closed = false;
      continue;
    }
    double end = to.Along;
    if (end < from.Along || (end == from.Along && (i + 1) % events.size() <= i))
    {
      end += perimeter;
    }
    double last[2] = { from.UV[0], from.UV[1] };
    for (int lap = 0; lap < 2; ++lap)
    {
      for (int side = 0; side < 4; ++side)
      {
        const double t = face.SideStart(side) + lap * perimeter;
        if (t > from.Along && t < end)
        {
          double corner[2];
          face.Corner(side, corner);
          twice += face.Cross(last, corner);
          std::copy_n(corner, 2, last);
        }
      }
    }
    twice += face.Cross(last, to.UV);
    cap.Covered.emplace_back(from.Along, to.Along);
  }
  cap.TwiceArea = twice;
}

/// The cap of face f, whose sides the outline never meets: all in or all out, as the
/// neighbouring faces' caps say along the shared side, else as the outline's own loops say
/// (holes: in).
void FillWholeFace(int f, FaceCap (&faces)[6], const VolumeBox& box)
{
  FaceCap& cap = faces[f];
  const Face face(f, box);
  int inside = -1;
  for (int g = 0; g < 6 && inside < 0; ++g)
  {
    if (!faces[g].HasEvents || g / 2 == f / 2)
    {
      continue;
    }
    const Face other(g, box);
    for (int side = 0; side < 4; ++side)
    {
      if (other.SideBits[side] == face.Bit)
      {
        const double middle =
          other.SideStart(side) + 0.5 * (side % 2 ? other.Height() : other.Width());
        inside = CoveredAt(faces[g], middle, other.Perimeter()) ? 1 : 0;
      }
    }
  }
  if (inside < 0)
  {
    inside = cap.TwiceLoopArea < 0 ? 1 : 0;
  }
  cap.TwiceArea = cap.TwiceLoopArea + (inside ? 2.0 * face.Width() * face.Height() : 0.0);
}

} // namespace

Caps BorderCaps(std::vector<BorderEdge> edges, const VolumeBox& box)
{
  const std::vector<BorderEdge> boundary = BoundaryEdges(edges);
  Caps caps;
  FaceCap faces[6];
  for (int f = 0; f < 6; ++f)
  {
    const Face face(f, box);
    std::vector<Event> events = OutlineEvents(boundary, face, faces[f], caps);
    if (!events.empty())
    {
      CloseAlongSides(events, face, faces[f], caps);
    }
  }
  for (int f = 0; f < 6; ++f)
  {
    if (!faces[f].HasEvents)
    {
      FillWholeFace(f, faces, box);
    }
  }
  for (int f = 0; f < 6; ++f)
  {
    if (faces[f].TwiceArea == 0.0)
    {
      continue;
    }
    const Face face(f, box);
    const int axis = f / 2;
    const double area = 0.5 * faces[f].TwiceArea * box.Spacing[face.U] * box.Spacing[face.V];
    const double distance =
      0.5 * (box.Extent[2 * axis + 1] - box.Extent[2 * axis]) * box.Spacing[axis];
    caps.SixVolume += 2.0 * distance * area;
    caps.Area += area;
    ++caps.Faces;
  }
  return caps;
}

} // namespace rgmc
