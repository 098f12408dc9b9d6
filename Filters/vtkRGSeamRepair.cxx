// Seam repair: global vertex numbering across ranks, global mesh checks, and smoothing that is
// the same on any number of ranks.
#include "vtkRGSeamRepair.h"

#include "rgmcGrid.h"
#include "rgmcKeyMap.h"
#include "rgmcSmoothing.h"
#include "vtkRGCollective.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkDummyController.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <type_traits>
#include <map>
#include <sstream>
#include <tuple>
#include <vector>

vtkStandardNewMacro(vtkRGSeamRepair);
vtkCxxSetObjectMacro(vtkRGSeamRepair, Controller, vtkMultiProcessController);

namespace
{

using rgmc::Ranks;
constexpr int NumberingTag = 48800, AnswerTag = 48802, EdgesTag = 48804, RequestTag = 48806,
              StateTag = 48808, UpdateTag = 48810, NormalTag = 48812, NormalBackTag = 48814;

// ---- vertex identities -----------------------------------------------------------------------

/// What makes copies of a vertex one vertex: its key (A), or its exact coordinates (A, B, C).
struct Identity
{
  std::uint64_t A = 0, B = 0, C = 0;
  bool operator<(const Identity& o) const { return std::tie(A, B, C) < std::tie(o.A, o.B, o.C); }
  bool operator==(const Identity& o) const { return A == o.A && B == o.B && C == o.C; }
};

std::uint64_t Bits(double v)
{
  v = v == 0.0 ? 0.0 : v; // -0 and +0 are one coordinate
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

void Append(std::vector<vtkIdType>& out, const Identity& id)
{
  for (std::uint64_t w : { id.A, id.B, id.C })
  {
    vtkIdType v;
    std::memcpy(&v, &w, sizeof v);
    out.push_back(v);
  }
}

Identity Read(const vtkIdType* p)
{
  Identity id;
  std::memcpy(&id.A, p, 8);
  std::memcpy(&id.B, p + 1, 8);
  std::memcpy(&id.C, p + 2, 8);
  return id;
}

vtkIdType PackDouble(double v)
{
  vtkIdType b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

double UnpackDouble(vtkIdType b)
{
  double v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

/// This rank's distinct vertices: sorted identities, an input point of each, and the vertex of
/// every input point.
struct LocalVertices
{
  std::vector<Identity> Ids;
  std::vector<vtkIdType> First;
  std::vector<vtkIdType> Of;
};

LocalVertices MergeLocal(vtkPolyData* input, vtkIdTypeArray* keys)
{
  const vtkIdType n = input->GetNumberOfPoints();
  std::vector<std::pair<Identity, vtkIdType>> all(static_cast<std::size_t>(n));
  for (vtkIdType p = 0; p < n; ++p)
  {
    Identity id;
    if (keys)
    {
      id.A = static_cast<std::uint64_t>(keys->GetValue(p));
    }
    else
    {
      double x[3];
      input->GetPoint(p, x);
      id.A = Bits(x[0]);
      id.B = Bits(x[1]);
      id.C = Bits(x[2]);
    }
    all[p] = { id, p };
  }
  std::sort(all.begin(), all.end());
  LocalVertices local;
  local.Of.resize(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < all.size(); ++i)
  {
    if (i == 0 || !(all[i].first == all[i - 1].first))
    {
      local.Ids.push_back(all[i].first);
      local.First.push_back(all[i].second);
    }
    local.Of[all[i].second] = static_cast<vtkIdType>(local.Ids.size() - 1);
  }
  return local;
}

// ---- global numbering --------------------------------------------------------------------------

/// Global id, owner and other holders of each of this rank's vertices.
struct Numbering
{
  std::vector<vtkIdType> Gid;
  std::vector<int> Owner;
  std::vector<vtkIdType> SharerOffsets{ 0 };
  std::vector<int> Sharers; // the other ranks that hold the vertex
  vtkIdType Total = 0;

  bool Shared(vtkIdType v) const { return this->SharerOffsets[v + 1] > this->SharerOffsets[v]; }
};

/// Numbers the identities of all ranks in their sorted order. Each rank sends its identities to
/// the rank responsible for their range (ranges from sampled identities), which groups equal
/// ones and answers with their global id, owner (lowest rank) and holders. Collective.
Numbering Number(Ranks& ranks, const std::vector<Identity>& ids)
{
  const int P = ranks.Size;
  // Ranges of about equal size, from up to 64 sampled identities per rank.
  std::vector<vtkIdType> samples;
  const std::size_t n = ids.size(), k = std::min<std::size_t>(n, 64);
  for (std::size_t i = 0; i < k; ++i)
  {
    Append(samples, ids[i * n / k]);
  }
  vtkIdType count = static_cast<vtkIdType>(samples.size());
  std::vector<vtkIdType> counts(P), offsets(P + 1, 0);
  ranks.C->AllGather(&count, counts.data(), 1);
  for (int r = 0; r < P; ++r)
  {
    offsets[r + 1] = offsets[r] + counts[r];
  }
  std::vector<vtkIdType> allSamples(static_cast<std::size_t>(offsets[P]) + 1);
  ranks.C->AllGatherV(samples.data(), allSamples.data(), count, counts.data(), offsets.data());
  std::vector<Identity> sorted;
  for (vtkIdType s = 0; s + 2 < offsets[P]; s += 3)
  {
    sorted.push_back(Read(&allSamples[s]));
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<Identity> splitters;
  for (int h = 1; h < P && !sorted.empty(); ++h)
  {
    splitters.push_back(sorted[h * sorted.size() / P]);
  }
  auto home = [&splitters](const Identity& id) {
    return static_cast<int>(std::upper_bound(splitters.begin(), splitters.end(), id) - splitters.begin());
  };

  // Identities to their ranges' ranks (in order: the ranges follow the sorted identities).
  std::vector<std::vector<vtkIdType>> outgoing(P);
  for (const Identity& id : ids)
  {
    Append(outgoing[home(id)], id);
  }
  const std::vector<bool> everyone(P, true);
  const auto incoming = ranks.Exchange(outgoing, everyone, NumberingTag);

  // Group equal identities; number them in order.
  struct Entry
  {
    Identity Id;
    int Source;
    vtkIdType Position;
  };
  std::vector<Entry> entries;
  for (int s = 0; s < P; ++s)
  {
    for (vtkIdType i = 0; i + 2 < static_cast<vtkIdType>(incoming[s].size()); i += 3)
    {
      entries.push_back(Entry{ Read(&incoming[s][i]), s, i / 3 });
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.Id < b.Id || (a.Id == b.Id && a.Source < b.Source);
  });
  std::vector<vtkIdType> groupOf(entries.size());
  vtkIdType groups = 0;
  for (std::size_t e = 0; e < entries.size(); ++e)
  {
    if (e > 0 && !(entries[e].Id == entries[e - 1].Id))
    {
      ++groups;
    }
    groupOf[e] = groups;
  }
  const vtkIdType unique = entries.empty() ? 0 : groups + 1;
  std::vector<vtkIdType> uniques(P), first(P + 1, 0);
  ranks.C->AllGather(&unique, uniques.data(), 1);
  for (int r = 0; r < P; ++r)
  {
    first[r + 1] = first[r] + uniques[r];
  }

  // Answers, per source in the order it sent: gid, owner, holders.
  std::vector<std::vector<vtkIdType>> answers(P);
  for (std::size_t e = 0; e < entries.size();)
  {
    std::size_t end = e;
    while (end < entries.size() && groupOf[end] == groupOf[e])
    {
      ++end;
    }
    for (std::size_t m = e; m < end; ++m)
    {
      std::vector<vtkIdType>& out = answers[entries[m].Source];
      out.push_back(first[ranks.Rank] + groupOf[e]);
      out.push_back(entries[e].Source); // the lowest holder owns the vertex
      out.push_back(static_cast<vtkIdType>(end - e));
      for (std::size_t h = e; h < end; ++h)
      {
        out.push_back(entries[h].Source);
      }
    }
    e = end;
  }
  // Each source's entries come in its own order, since its identities were sorted.
  const auto replies = ranks.Exchange(answers, everyone, AnswerTag);

  Numbering numbering;
  numbering.Total = first[P];
  numbering.Gid.reserve(n);
  numbering.Owner.reserve(n);
  for (int h = 0; h < P; ++h)
  {
    const std::vector<vtkIdType>& in = replies[h];
    for (std::size_t i = 0; i < in.size();)
    {
      numbering.Gid.push_back(in[i]);
      numbering.Owner.push_back(static_cast<int>(in[i + 1]));
      const vtkIdType holders = in[i + 2];
      for (vtkIdType j = 0; j < holders; ++j)
      {
        const int holder = static_cast<int>(in[i + 3 + j]);
        if (holder != ranks.Rank)
        {
          numbering.Sharers.push_back(holder);
        }
      }
      numbering.SharerOffsets.push_back(static_cast<vtkIdType>(numbering.Sharers.size()));
      i += 3 + static_cast<std::size_t>(holders);
    }
  }
  return numbering;
}

// ---- the mesh around each owned vertex ---------------------------------------------------------

/// Which faces of the volume a vertex lies on (bits x-, x+, y-, y+, z-, z+): an edge whose two
/// vertices share a face runs along the volume's border.
struct BorderTest
{
  bool Keys = false;
  int Whole[6] = { 0, -1, 0, -1, 0, -1 };
  double Bounds[6] = { 0, 0, 0, 0, 0, 0 };
  double Tolerance = 0.0;

  int Mask(const rgmc::Grid& grid, vtkIdType key, const double x[3]) const
  {
    int mask = 0;
    if (this->Keys)
    {
      int p[3], axis;
      grid.Decode(key, p, axis);
      for (int b = 0; b < 3; ++b)
      {
        if (b != axis)
        {
          mask |= (p[b] == this->Whole[2 * b]) << (2 * b);
          mask |= (p[b] == this->Whole[2 * b + 1]) << (2 * b + 1);
        }
      }
      return mask;
    }
    for (int b = 0; b < 3; ++b)
    {
      mask |= (std::fabs(x[b] - this->Bounds[2 * b]) <= this->Tolerance) << (2 * b);
      mask |= (std::fabs(x[b] - this->Bounds[2 * b + 1]) <= this->Tolerance) << (2 * b + 1);
    }
    return mask;
  }
};

/// A neighbour of an owned vertex, on the whole mesh.
struct Neighbour
{
  vtkIdType Gid;
  int Uses;
  vtkIdType Local; // index into this rank's vertices, or -1
  int Provider;    // a rank that holds it, when not local
  int Mask;
  double X[3];
};

struct Checks
{
  vtkIdType Edges = 0, Boundary = 0, Border = 0, NonManifold = 0;
};

template <typename T>
class Repair
{
public:
  Repair(Ranks& ranks, vtkPolyData* input, const LocalVertices& local, const Numbering& numbering,
    const BorderTest& border)
    : R(ranks)
    , Input(input)
    , Local(local)
    , Num(numbering)
    , Border(border)
    , N(static_cast<vtkIdType>(local.Ids.size()))
    , Index(2 * local.Ids.size() + 16)
  {
    // Positions of the vertices, in the input's precision.
    this->X.resize(3 * this->N);
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      double x[3];
      input->GetPoint(local.First[v], x);
      for (int k = 0; k < 3; ++k)
      {
        this->X[3 * v + k] = static_cast<T>(x[k]);
      }
      bool inserted;
      this->Index.FindOrInsert(numbering.Gid[v], static_cast<std::int32_t>(v), inserted);
    }
    const rgmc::Grid grid(border.Whole, border.Whole);
    this->Masks.resize(this->N);
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      const double x[3] = { static_cast<double>(this->X[3 * v]),
        static_cast<double>(this->X[3 * v + 1]), static_cast<double>(this->X[3 * v + 2]) };
      this->Masks[v] = border.Mask(grid, static_cast<vtkIdType>(local.Ids[v].A), x);
    }
    // Triangles over the vertices.
    vtkCellArray* polys = input->GetPolys();
    this->Triangles.reserve(3 * polys->GetNumberOfCells());
    vtkIdType npts;
    const vtkIdType* pts;
    for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
    {
      for (int k = 0; k < 3; ++k)
      {
        this->Triangles.push_back(local.Of[pts[k]]);
      }
    }
    this->Partners.assign(ranks.Size, false);
    for (int s : numbering.Sharers)
    {
      this->Partners[s] = true;
    }
  }

  /// The edges at each vertex (with repeats: once per triangle side), gathered at owners;
  /// smoothing stencils of owned vertices; global checks. Collective.
  Checks Analyze()
  {
    // This rank's edges at each vertex, in compressed rows, sorted by the neighbour's gid.
    std::vector<vtkIdType> offsets(this->N + 1, 0);
    for (std::size_t t = 0; t < this->Triangles.size(); t += 3)
    {
      for (int k = 0; k < 3; ++k)
      {
        offsets[this->Triangles[t + k] + 1] += 2;
      }
    }
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      offsets[v + 1] += offsets[v];
    }
    std::vector<vtkIdType> ends(offsets.begin(), offsets.end() - 1), edges(offsets[this->N]);
    for (std::size_t t = 0; t < this->Triangles.size(); t += 3)
    {
      for (int k = 0; k < 3; ++k)
      {
        const vtkIdType v = this->Triangles[t + k];
        edges[ends[v]++] = this->Triangles[t + (k + 1) % 3];
        edges[ends[v]++] = this->Triangles[t + (k + 2) % 3];
      }
    }
    const std::vector<vtkIdType>& gid = this->Num.Gid;
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      std::sort(edges.begin() + offsets[v], edges.begin() + offsets[v + 1],
        [&gid](vtkIdType a, vtkIdType b) { return gid[a] < gid[b]; });
    }
    auto localNeighbours = [&](vtkIdType v, std::vector<Neighbour>& out) {
      for (vtkIdType e = offsets[v]; e < offsets[v + 1];)
      {
        vtkIdType end = e;
        while (end < offsets[v + 1] && edges[end] == edges[e])
        {
          ++end;
        }
        const vtkIdType w = edges[e];
        Neighbour nb{ gid[w], static_cast<int>(end - e), w, this->R.Rank, 0, { 0, 0, 0 } };
        for (int k = 0; k < 3; ++k)
        {
          nb.X[k] = static_cast<double>(this->X[3 * w + k]);
        }
        nb.Mask = this->MaskOf(w);
        out.push_back(nb);
        e = end;
      }
    };

    // Edges at shared vertices go to their owners.
    std::vector<std::vector<vtkIdType>> outgoing(this->R.Size);
    std::vector<Neighbour> scratch;
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      const int owner = this->Num.Owner[v];
      if (owner == this->R.Rank || !this->Num.Shared(v))
      {
        continue;
      }
      scratch.clear();
      localNeighbours(v, scratch);
      std::vector<vtkIdType>& out = outgoing[owner];
      out.push_back(gid[v]);
      out.push_back(static_cast<vtkIdType>(scratch.size()));
      for (const Neighbour& nb : scratch)
      {
        out.insert(out.end(), { nb.Gid, nb.Uses, nb.Mask, PackDouble(nb.X[0]),
                                PackDouble(nb.X[1]), PackDouble(nb.X[2]) });
      }
    }
    const auto incoming = this->R.Exchange(outgoing, this->Partners, EdgesTag);
    std::map<vtkIdType, std::vector<Neighbour>> received; // by the owned vertex's gid
    for (int s = 0; s < this->R.Size; ++s)
    {
      const std::vector<vtkIdType>& in = incoming[s];
      if (s == this->R.Rank)
      {
        continue;
      }
      for (std::size_t i = 0; i < in.size();)
      {
        std::vector<Neighbour>& list = received[in[i]];
        const vtkIdType count = in[i + 1];
        i += 2;
        for (vtkIdType j = 0; j < count; ++j, i += 6)
        {
          Neighbour nb{ in[i], static_cast<int>(in[i + 1]), -1, s, static_cast<int>(in[i + 2]),
            { UnpackDouble(in[i + 3]), UnpackDouble(in[i + 4]), UnpackDouble(in[i + 5]) } };
          if (const std::int32_t* w = this->Index.Find(nb.Gid))
          {
            nb.Local = *w;
          }
          list.push_back(nb);
        }
      }
    }

    // Every owned vertex: its whole neighbourhood, the checks, its stencil.
    Checks checks;
    std::vector<Neighbour> all;
    std::vector<rgmc::IncidentEdge> incident;
    std::map<vtkIdType, vtkIdType> remoteSlot; // gid -> slot among the remote neighbours
    const double cosEdgeAngle = std::cos(vtkMath::RadiansFromDegrees(15.0));
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      if (this->Num.Owner[v] != this->R.Rank)
      {
        continue;
      }
      all.clear();
      localNeighbours(v, all);
      auto more = received.find(gid[v]);
      if (more != received.end())
      {
        all.insert(all.end(), more->second.begin(), more->second.end());
        std::stable_sort(all.begin(), all.end(),
          [](const Neighbour& a, const Neighbour& b) { return a.Gid < b.Gid; });
        // Merge the ranks' counts of each edge; keep a local copy of the neighbour if any.
        std::size_t kept = 0;
        for (std::size_t i = 0; i < all.size(); ++i)
        {
          if (kept > 0 && all[kept - 1].Gid == all[i].Gid)
          {
            all[kept - 1].Uses += all[i].Uses;
            if (all[kept - 1].Local < 0 && all[i].Local >= 0)
            {
              all[kept - 1].Local = all[i].Local;
            }
          }
          else
          {
            all[kept++] = all[i];
          }
        }
        all.resize(kept);
      }
      const int myMask = this->MaskOf(v);
      incident.clear();
      for (const Neighbour& nb : all)
      {
        incident.push_back(rgmc::IncidentEdge{ nb.Gid, nb.Uses });
        if (nb.Gid > gid[v])
        {
          ++checks.Edges;
          if (nb.Uses == 1)
          {
            ++((myMask & nb.Mask) ? checks.Border : checks.Boundary);
          }
          else if (nb.Uses > 2)
          {
            ++checks.NonManifold;
          }
        }
      }
      auto position = [&](vtkIdType g, T x[3]) {
        for (const Neighbour& nb : all)
        {
          if (nb.Gid == g)
          {
            for (int k = 0; k < 3; ++k)
            {
              x[k] = static_cast<T>(nb.X[k]);
            }
          }
        }
      };
      const std::vector<std::int64_t> stencil = rgmc::SmoothingStencil(
        incident, [&](std::int64_t a, std::int64_t b) {
          T pa[3], pb[3];
          position(a, pa);
          position(b, pb);
          return rgmc::ExceedsEdgeAngle(pa, &this->X[3 * v], pb, cosEdgeAngle);
        });
      std::vector<std::int64_t> slots;
      for (std::int64_t g : stencil)
      {
        const Neighbour* nb = nullptr;
        for (const Neighbour& candidate : all)
        {
          nb = candidate.Gid == g ? &candidate : nb;
        }
        if (nb->Local >= 0)
        {
          slots.push_back(nb->Local);
          continue;
        }
        auto found = remoteSlot.find(g);
        if (found == remoteSlot.end())
        {
          found = remoteSlot.emplace(g, static_cast<vtkIdType>(this->RemoteGids.size())).first;
          this->RemoteGids.push_back(g);
          this->RemoteProviders.push_back(nb->Provider);
          this->RemoteInitial.insert(this->RemoteInitial.end(), nb->X, nb->X + 3);
        }
        slots.push_back(-1 - found->second); // remote: resolved to N + slot below
      }
      this->Owned.push_back(v);
      this->Stencil.Add(slots);
    }
    for (std::int64_t& s : this->Stencil.Neighbours)
    {
      s = s < 0 ? this->N + (-1 - s) : s;
    }
    this->PlanExchanges();
    return checks;
  }

  /// Smooths in place (positions of this rank's vertices, in the input's precision).
  /// Returns false when aborted. Collective.
  bool Smooth(int method, int iterations, double relaxation, double passBand,
    rgmc::SincWindow window, const std::function<bool(double)>& progress)
  {
    const std::size_t size = 3 * (this->N + this->RemoteGids.size());
    std::vector<T> a(size), b(size);
    std::copy(this->X.begin(), this->X.end(), a.begin());
    for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
    {
      for (int k = 0; k < 3; ++k)
      {
        a[3 * (this->N + r) + k] = static_cast<T>(this->RemoteInitial[3 * r + k]);
      }
    }
    if (method == vtkRGSeamRepair::LAPLACIAN)
    {
      for (int it = 0; it < iterations; ++it)
      {
        if (progress(double(it) / iterations))
        {
          return false;
        }
        this->Fetch(a.data());
        rgmc::LaplacianStep(this->Stencil, this->Owned, a.data(), b.data(), relaxation);
        this->Update(b.data());
        std::swap(a, b);
      }
      std::copy(a.begin(), a.begin() + 3 * this->N, this->X.begin());
      return true;
    }
    // Windowed sinc: x0 = a, x1 = b, x2 = c, x3 = sum.
    const std::vector<double> coefficients = rgmc::SincCoefficients(iterations, passBand, window);
    std::vector<T> c(size), sum(size);
    T* x0 = a.data();
    T* x1 = b.data();
    T* x2 = c.data();
    this->Fetch(x0);
    rgmc::SincFirstStep(this->Stencil, this->Owned, x0, x1, sum.data(), coefficients.data());
    this->Update(x1);
    for (int it = 2; it <= iterations; ++it)
    {
      if (progress(double(it) / iterations))
      {
        return false;
      }
      this->Fetch(x1);
      rgmc::SincStep(this->Stencil, this->Owned, x0, x1, x2, sum.data(), coefficients[it]);
      this->Update(x2);
      T* oldest = x0;
      x0 = x1;
      x1 = x2;
      x2 = oldest;
    }
    this->Update(sum.data());
    std::copy(sum.begin(), sum.begin() + 3 * this->N, this->X.begin());
    return true;
  }

  /// Area-weighted vertex normals of the current positions, summed at owners. Collective.
  std::vector<float> Normals()
  {
    std::vector<double> n(3 * this->N, 0.0);
    for (std::size_t t = 0; t < this->Triangles.size(); t += 3)
    {
      const T* p0 = &this->X[3 * this->Triangles[t]];
      const T* p1 = &this->X[3 * this->Triangles[t + 1]];
      const T* p2 = &this->X[3 * this->Triangles[t + 2]];
      double e1[3], e2[3], cross[3];
      for (int k = 0; k < 3; ++k)
      {
        e1[k] = static_cast<double>(p1[k]) - static_cast<double>(p0[k]);
        e2[k] = static_cast<double>(p2[k]) - static_cast<double>(p0[k]);
      }
      vtkMath::Cross(e1, e2, cross);
      for (int k = 0; k < 3; ++k)
      {
        for (int corner = 0; corner < 3; ++corner)
        {
          n[3 * this->Triangles[t + corner] + k] += cross[k];
        }
      }
    }
    // Partial sums of shared vertices to their owners, added in rank order; results back.
    std::vector<std::vector<double>> partial(this->R.Size);
    for (int o = 0; o < this->R.Size; ++o)
    {
      for (vtkIdType v : this->FromOwner[o])
      {
        partial[o].insert(partial[o].end(), &n[3 * v], &n[3 * v] + 3);
      }
    }
    const auto sums = this->R.Exchange(partial, this->Partners, NormalTag);
    for (int s = 0; s < this->R.Size; ++s)
    {
      if (s == this->R.Rank)
      {
        continue;
      }
      const std::vector<vtkIdType>& list = this->ToSharer[s];
      for (std::size_t i = 0; i < list.size(); ++i)
      {
        for (int k = 0; k < 3; ++k)
        {
          n[3 * list[i] + k] += sums[s][3 * i + k];
        }
      }
    }
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      vtkMath::Normalize(&n[3 * v]);
    }
    this->Update(n.data(), NormalBackTag);
    return std::vector<float>(n.begin(), n.end());
  }

  std::vector<T> X;                  // positions of this rank's vertices
  std::vector<vtkIdType> Triangles;  // over this rank's vertices

private:
  int MaskOf(vtkIdType v) const { return this->Masks[v]; }

  /// Who sends what each iteration: the neighbours owners lack, from ranks that hold them; the
  /// owners' new positions, to the other holders. Collective.
  void PlanExchanges()
  {
    std::vector<std::vector<vtkIdType>> requests(this->R.Size);
    for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
    {
      requests[this->RemoteProviders[r]].push_back(this->RemoteGids[r]);
      this->RemoteOrder[this->RemoteProviders[r]].push_back(this->N + static_cast<vtkIdType>(r));
    }
    const auto asked = this->R.Exchange(requests, this->Partners, RequestTag);
    for (int s = 0; s < this->R.Size; ++s)
    {
      for (vtkIdType g : asked[s])
      {
        this->Provide[s].push_back(*this->Index.Find(g));
      }
    }
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      const int owner = this->Num.Owner[v];
      if (owner == this->R.Rank)
      {
        for (vtkIdType s = this->Num.SharerOffsets[v]; s < this->Num.SharerOffsets[v + 1]; ++s)
        {
          this->ToSharer[this->Num.Sharers[s]].push_back(v);
        }
      }
      else
      {
        this->FromOwner[owner].push_back(v);
      }
    }
    // Both sides list a pair's vertices in gid order (this rank's vertices are in that order).
  }

  static void Gather(const std::vector<vtkIdType>& list, const T* state, std::vector<double>& out)
  {
    for (vtkIdType v : list)
    {
      out.insert(out.end(), state + 3 * v, state + 3 * v + 3);
    }
  }

  /// Fills the remote slots of `state` with the neighbours' states from their holders.
  void Fetch(T* state)
  {
    std::vector<std::vector<double>> out(this->R.Size);
    for (int s = 0; s < this->R.Size; ++s)
    {
      Gather(this->Provide[s], state, out[s]);
    }
    const auto in = this->R.Exchange(out, this->Partners, StateTag);
    for (int s = 0; s < this->R.Size; ++s)
    {
      const std::vector<vtkIdType>& slots = this->RemoteOrder[s];
      for (std::size_t i = 0; i < slots.size(); ++i)
      {
        for (int k = 0; k < 3; ++k)
        {
          state[3 * slots[i] + k] = static_cast<T>(in[s][3 * i + k]);
        }
      }
    }
  }

  /// Sends the owned shared vertices' `state` to their other holders.
  template <typename S>
  void Update(S* state, int tag = UpdateTag)
  {
    std::vector<std::vector<double>> out(this->R.Size);
    for (int s = 0; s < this->R.Size; ++s)
    {
      for (vtkIdType v : this->ToSharer[s])
      {
        out[s].insert(out[s].end(), state + 3 * v, state + 3 * v + 3);
      }
    }
    const auto in = this->R.Exchange(out, this->Partners, tag);
    for (int o = 0; o < this->R.Size; ++o)
    {
      if (o == this->R.Rank)
      {
        continue;
      }
      const std::vector<vtkIdType>& list = this->FromOwner[o];
      for (std::size_t i = 0; i < list.size(); ++i)
      {
        for (int k = 0; k < 3; ++k)
        {
          state[3 * list[i] + k] = static_cast<S>(in[o][3 * i + k]);
        }
      }
    }
  }

  Ranks& R;
  vtkPolyData* Input;
  const LocalVertices& Local;
  const Numbering& Num;
  BorderTest Border;
  const vtkIdType N;
  rgmc::KeyMap Index; // gid -> this rank's vertex
  std::vector<int> Masks; // the volume faces each vertex lies on
  std::vector<bool> Partners;

  std::vector<std::int64_t> Owned; // the vertices this rank moves, one stencil row each
  rgmc::Stencils Stencil;
  std::vector<vtkIdType> RemoteGids; // neighbours of owned vertices held elsewhere
  std::vector<int> RemoteProviders;
  std::vector<double> RemoteInitial;
  std::map<int, std::vector<vtkIdType>> RemoteOrder; // provider -> slots, in request order
  std::map<int, std::vector<vtkIdType>> Provide;     // requester -> vertices to send
  std::map<int, std::vector<vtkIdType>> ToSharer;    // holder -> owned shared vertices
  std::map<int, std::vector<vtkIdType>> FromOwner;   // owner -> vertices it updates here
};

} // namespace

//------------------------------------------------------------------------------
vtkRGSeamRepair::vtkRGSeamRepair()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGSeamRepair::~vtkRGSeamRepair()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
int vtkRGSeamRepair::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* input = vtkPolyData::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  vtkNew<vtkDummyController> single;
  Ranks ranks(this->Controller ? this->Controller : single.Get());
  // A new run: an abort of an earlier run does not carry over (VTK 9.2 cleared the flag itself;
  // VTK 9.3 and later keep it, so an aborted filter would stay empty). Set directly, as
  // SetAbortExecute would mark the filter modified and make it run again.
  this->AbortExecute = 0;

  // PASS 0: a triangle mesh, on every rank.
  std::string problem;
  {
    std::ostringstream msg;
    const vtkIdType verts = input->GetNumberOfVerts(), lines = input->GetNumberOfLines(),
                    strips = input->GetNumberOfStrips();
    vtkIdType other = 0;
    vtkCellArray* polys = input->GetPolys();
    vtkIdType npts;
    const vtkIdType* pts;
    for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
    {
      other += npts != 3;
    }
    if (verts || lines || strips || other)
    {
      msg << "the input is not a triangle mesh: it has " << verts << " vertex cells, " << lines
          << " lines, " << strips << " triangle strips and " << other
          << " polygons that are not triangles (apply Triangulate, or Extract Surface, first)";
    }
    problem = msg.str();
  }
  if (!ranks.Agree(problem.empty(), problem))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << problem << ".");
    return 0;
  }
  vtkIdType localTriangles = input->GetNumberOfPolys(), triangles = 0;
  ranks.C->AllReduce(&localTriangles, &triangles, 1, vtkCommunicator::SUM_OP);
  if (triangles == 0)
  {
    vtkErrorMacro(<< "Cannot repair the seams: the input has no triangles.");
    return 0;
  }
  this->UpdateProgress(0.05);

  // Vertex identities: global ids when every rank with points has them, else coordinates.
  vtkIdTypeArray* keys = vtkIdTypeArray::SafeDownCast(input->GetPointData()->GetGlobalIds());
  int keyed = input->GetNumberOfPoints() == 0 || keys ? 1 : 0, allKeyed = 0;
  ranks.C->AllReduce(&keyed, &allKeyed, 1, vtkCommunicator::MIN_OP);
  const LocalVertices local = MergeLocal(input, allKeyed ? keys : nullptr);
  const Numbering numbering = Number(ranks, local.Ids);
  this->UpdateProgress(0.25);

  // How to tell edges on the volume's border: from keys and the whole extent when the input
  // came from vtkRGMarchingCubes, else from the global bounds.
  BorderTest border;
  {
    double b[6], lo[3], hi[3], glo[3], ghi[3];
    input->GetBounds(b);
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = input->GetNumberOfPoints() ? b[2 * a] : VTK_DOUBLE_MAX;
      hi[a] = input->GetNumberOfPoints() ? b[2 * a + 1] : VTK_DOUBLE_MIN;
    }
    ranks.C->AllReduce(lo, glo, 3, vtkCommunicator::MIN_OP);
    ranks.C->AllReduce(hi, ghi, 3, vtkCommunicator::MAX_OP);
    double diagonal = 0;
    for (int a = 0; a < 3; ++a)
    {
      border.Bounds[2 * a] = glo[a];
      border.Bounds[2 * a + 1] = ghi[a];
      diagonal += (ghi[a] - glo[a]) * (ghi[a] - glo[a]);
    }
    border.Tolerance = 1e-6 * std::sqrt(diagonal);
    vtkIntArray* whole = vtkIntArray::SafeDownCast(input->GetFieldData()->GetArray("WholeExtent"));
    if (allKeyed && whole && whole->GetNumberOfValues() == 6)
    {
      border.Keys = true;
      for (int i = 0; i < 6; ++i)
      {
        border.Whole[i] = whole->GetValue(i);
      }
    }
  }

  // The repair proper, in the input points' precision.
  vtkNew<vtkPoints> points;
  std::vector<vtkIdType> connectivity;
  std::vector<float> normals;
  Checks checks;
  bool aborted = false;
  auto progress = [this, &ranks](double fraction) {
    this->UpdateProgress(0.4 + 0.5 * fraction);
    return ranks.Any(this->CheckAbort());
  };
  auto run = [&](auto zero) {
    using T = decltype(zero);
    Repair<T> repair(ranks, input, local, numbering, border);
    checks = repair.Analyze();
    this->UpdateProgress(0.4);
    const bool smooth = this->SmoothingMethod != NO_SMOOTHING && this->NumberOfIterations > 0;
    if (smooth)
    {
      aborted = !repair.Smooth(this->SmoothingMethod, this->NumberOfIterations,
        this->RelaxationFactor, this->PassBand,
        this->WindowFunction == HAMMING_WINDOW ? rgmc::SincWindow::Hamming
                                               : rgmc::SincWindow::Nuttall,
        progress);
      if (!aborted)
      {
        normals = repair.Normals();
      }
    }
    points->SetDataType(std::is_same<T, float>::value ? VTK_FLOAT : VTK_DOUBLE);
    points->SetNumberOfPoints(static_cast<vtkIdType>(local.Ids.size()));
    for (std::size_t v = 0; v < local.Ids.size(); ++v)
    {
      points->SetPoint(static_cast<vtkIdType>(v), static_cast<double>(repair.X[3 * v]),
        static_cast<double>(repair.X[3 * v + 1]), static_cast<double>(repair.X[3 * v + 2]));
    }
    connectivity.swap(repair.Triangles);
  };
  if (input->GetPoints() && input->GetPoints()->GetDataType() == VTK_FLOAT)
  {
    run(float());
  }
  else
  {
    run(double());
  }
  if (aborted)
  {
    output->Initialize();
    return 1;
  }

  // Global checks.
  vtkIdType counts[4] = { checks.Edges, checks.Boundary, checks.Border, checks.NonManifold },
            sums[4];
  ranks.C->AllReduce(counts, sums, 4, vtkCommunicator::SUM_OP);
  const vtkIdType euler = numbering.Total - sums[0] + triangles;
  const bool closed = sums[1] == 0 && sums[3] == 0;

  // PASS 5: the output.
  const vtkIdType n = static_cast<vtkIdType>(local.Ids.size());
  output->Initialize();
  output->SetPoints(points);
  vtkNew<vtkCellArray> polys;
  {
    vtkNew<vtkIdTypeArray> offsets, conn;
    const vtkIdType numTris = static_cast<vtkIdType>(connectivity.size() / 3);
    offsets->SetNumberOfTuples(numTris + 1);
    for (vtkIdType t = 0; t <= numTris; ++t)
    {
      offsets->SetValue(t, 3 * t);
    }
    conn->SetNumberOfTuples(static_cast<vtkIdType>(connectivity.size()));
    std::copy(connectivity.begin(), connectivity.end(), conn->GetPointer(0));
    polys->SetData(offsets, conn);
  }
  output->SetPolys(polys);
  output->GetCellData()->PassData(input->GetCellData());

  vtkPointData* pd = output->GetPointData();
  pd->CopyGlobalIdsOff();
  const bool smoothed = !normals.empty();
  if (smoothed)
  {
    pd->CopyNormalsOff();
  }
  pd->CopyAllocate(input->GetPointData(), n);
  for (vtkIdType v = 0; v < n; ++v)
  {
    pd->CopyData(input->GetPointData(), local.First[v], v);
  }
  vtkNew<vtkIdTypeArray> gids;
  gids->SetName("GlobalPointIds");
  gids->SetNumberOfTuples(n);
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfTuples(n);
  for (vtkIdType v = 0; v < n; ++v)
  {
    gids->SetValue(v, numbering.Gid[v]);
    ghosts->SetValue(v, numbering.Owner[v] == ranks.Rank ? 0 : vtkDataSetAttributes::DUPLICATEPOINT);
  }
  pd->SetGlobalIds(gids);
  pd->AddArray(ghosts);
  if (smoothed)
  {
    vtkNew<vtkFloatArray> normalArray;
    normalArray->SetName("Normals");
    normalArray->SetNumberOfComponents(3);
    normalArray->SetNumberOfTuples(n);
    std::copy(normals.begin(), normals.end(), normalArray->GetPointer(0));
    pd->SetNormals(normalArray);
  }

  vtkFieldData* fd = output->GetFieldData();
  fd->PassData(input->GetFieldData());
  auto add = [fd](const char* name, vtkIdType value) {
    vtkNew<vtkIdTypeArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  add("UniquePoints", numbering.Total);
  add("Triangles", triangles);
  add("Edges", sums[0]);
  add("BoundaryEdges", sums[1]);
  add("VolumeBorderEdges", sums[2]);
  add("NonManifoldEdges", sums[3]);
  add("EulerCharacteristic", euler);
  add("Closed", closed ? 1 : 0);
  if (ranks.Rank == 0)
  {
    vtkLogF(INFO,
      "Seam repair: %lld unique points, %lld triangles, %lld edges, %lld boundary edges (%lld "
      "more on the volume's border), %lld non-manifold edges, Euler characteristic %lld: %s.",
      static_cast<long long>(numbering.Total), static_cast<long long>(triangles),
      static_cast<long long>(sums[0]), static_cast<long long>(sums[1]),
      static_cast<long long>(sums[2]), static_cast<long long>(sums[3]),
      static_cast<long long>(euler), closed ? "closed" : "not closed");
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkRGSeamRepair::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SmoothingMethod: " << this->SmoothingMethod << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "RelaxationFactor: " << this->RelaxationFactor << "\n";
  os << indent << "PassBand: " << this->PassBand << "\n";
  os << indent << "WindowFunction: " << (this->WindowFunction == HAMMING_WINDOW ? "Hamming" : "Nuttall")
     << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}
