// Quadric-error edge collapse on one block (see rgmcDecimation.h).
#include "rgmcDecimation.h"

#include "rgmcMinHeap.h"

#include <algorithm>
#include <cmath>

namespace rgmc
{

Quadric Quadric::OfTriangle(
  const double a[3], const double b[3], const double c[3], bool areaWeighted)
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  Quadric q;
  if (!(length > 0.0) || !std::isfinite(length))
  {
    return q;
  }
  n[0] /= length;
  n[1] /= length;
  n[2] /= length;
  const double d = -(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]);
  q.Terms = { n[0] * n[0], n[0] * n[1], n[0] * n[2], n[0] * d, n[1] * n[1], n[1] * n[2], n[1] * d,
    n[2] * n[2], n[2] * d, d * d };
  if (areaWeighted)
  {
    const double area = 0.5 * length;
    for (double& term : q.Terms)
    {
      term *= area;
    }
  }
  return q;
}

double Quadric::Error(const double p[3]) const
{
  const auto& q = this->Terms;
  const double x = p[0], y = p[1], z = p[2];
  return x * (q[0] * x + 2.0 * (q[1] * y + q[2] * z + q[3])) +
    y * (q[4] * y + 2.0 * (q[5] * z + q[6])) + z * (q[7] * z + 2.0 * q[8]) + q[9];
}

double PlaceCollapse(const Quadric& q, const double pa[3], const double pb[3], double position[3])
{
  const auto& m = q.Terms;
  const double mid[3] = { 0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2]) };
  const double d[3] = { pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2] };
  const double edge2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  auto take = [&q, position](const double x[3])
  {
    std::copy(x, x + 3, position);
    return q.Error(x);
  };
  double cost = HUGE_VAL;
  // A x = -b by Cramer's rule.
  const double c00 = m[4] * m[7] - m[5] * m[5];
  const double c01 = m[2] * m[5] - m[1] * m[7];
  const double c02 = m[1] * m[5] - m[2] * m[4];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  const double trace = m[0] + m[4] + m[7];
  if (trace > 0.0 && std::abs(det) > 1e-10 * trace * trace * trace)
  {
    const double c11 = m[0] * m[7] - m[2] * m[2];
    const double c12 = m[1] * m[2] - m[0] * m[5];
    const double c22 = m[0] * m[4] - m[1] * m[1];
    const double r[3] = { -m[3], -m[6], -m[8] };
    const double x[3] = { (c00 * r[0] + c01 * r[1] + c02 * r[2]) / det,
      (c01 * r[0] + c11 * r[1] + c12 * r[2]) / det, (c02 * r[0] + c12 * r[1] + c22 * r[2]) / det };
    const double d2 = (x[0] - mid[0]) * (x[0] - mid[0]) + (x[1] - mid[1]) * (x[1] - mid[1]) +
      (x[2] - mid[2]) * (x[2] - mid[2]);
    if (std::isfinite(d2) && d2 <= 4.0 * edge2)
    {
      cost = take(x);
    }
  }
  if (!std::isfinite(cost))
  {
    // On the edge pa + t d: Q = Q(pa) + 2 t g.d + t^2 d.A d, g = A pa + b.
    const double ad[3] = { m[0] * d[0] + m[1] * d[1] + m[2] * d[2],
      m[1] * d[0] + m[4] * d[1] + m[5] * d[2], m[2] * d[0] + m[5] * d[1] + m[7] * d[2] };
    const double g[3] = { m[0] * pa[0] + m[1] * pa[1] + m[2] * pa[2] + m[3],
      m[1] * pa[0] + m[4] * pa[1] + m[5] * pa[2] + m[6],
      m[2] * pa[0] + m[5] * pa[1] + m[7] * pa[2] + m[8] };
    const double curvature = d[0] * ad[0] + d[1] * ad[1] + d[2] * ad[2];
    const double slope = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
    if (curvature > 0.0)
    {
      const double t = std::min(1.0, std::max(0.0, -slope / curvature));
      const double x[3] = { pa[0] + t * d[0], pa[1] + t * d[1], pa[2] + t * d[2] };
      cost = take(x);
    }
  }
  if (!std::isfinite(cost))
  {
    cost = take(mid);
    for (const double* end : { pa, pb })
    {
      const double e = q.Error(end);
      if (e < cost)
      {
        std::copy(end, end + 3, position);
        cost = e;
      }
    }
  }
  return std::isfinite(cost) ? std::max(0.0, cost) : HUGE_VAL;
}

namespace
{

std::array<int, 3> Rotated(const std::array<int, 3>& t)
{
  if (t[1] < t[0] && t[1] < t[2])
  {
    return { t[1], t[2], t[0] };
  }
  if (t[2] < t[0] && t[2] < t[1])
  {
    return { t[2], t[0], t[1] };
  }
  return t;
}

void Cross(const double* a, const double* b, const double* c, double n[3])
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
}

// A candidate collapse in the queue: 16 bytes, so that a node's four children in the heap fill
// one cache line. It holds no record of when it was made: it is stale when its cost is no longer
// the edge's (see EdgeCollapser::Run).
struct Candidate
{
  double Cost;
  std::uint64_t Edge; // A << 32 | B, A < B: the order of their global ids

  Candidate() = default;
  Candidate(double cost, int a, int b)
    : Cost(cost)
    , Edge(static_cast<std::uint64_t>(a) << 32 | static_cast<std::uint32_t>(b))
  {
  }
  int A() const { return static_cast<int>(this->Edge >> 32); }
  int B() const { return static_cast<int>(this->Edge & 0xffffffffu); }

  // The queue's top: the cheapest, then the lowest (A, B), a total order on the keys.
  struct Cheaper
  {
    bool operator()(const Candidate& x, const Candidate& y) const
    {
      return x.Cost != y.Cost ? x.Cost < y.Cost : x.Edge < y.Edge;
    }
  };
};

// The live triangles around each vertex, in one pool: vertex v's are the first Count[v] of the
// Room[v] places from Start[v]. A star that outgrows its room moves to the pool's end with twice
// the room. One allocation for a block, where a list of its own for each vertex costs several.
class TriangleStars
{
public:
  /// Each vertex's triangles in increasing order, with room for `slack` more.
  void Build(std::size_t vertices, const std::vector<std::array<int, 3>>& triangles, int slack)
  {
    this->Count.assign(vertices, 0);
    for (const auto& t : triangles)
    {
      ++this->Count[t[0]], ++this->Count[t[1]], ++this->Count[t[2]];
    }
    this->Start.resize(vertices);
    this->Room.resize(vertices);
    std::size_t at = 0;
    for (std::size_t v = 0; v < vertices; ++v)
    {
      this->Start[v] = at;
      this->Room[v] = this->Count[v] + slack;
      at += this->Room[v];
      this->Count[v] = 0;
    }
    this->Pool.assign(at, -1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
    {
      for (int v : triangles[t])
      {
        this->Pool[this->Start[v] + this->Count[v]++] = static_cast<int>(t);
      }
    }
  }

  struct Span
  {
    const int* First;
    const int* Last;
    const int* begin() const { return this->First; }
    const int* end() const { return this->Last; }
    std::size_t size() const { return static_cast<std::size_t>(this->Last - this->First); }
  };

  /// v's triangles; valid until the next Push.
  Span operator[](int v) const
  {
    const int* first = this->Pool.data() + this->Start[v];
    return Span{ first, first + this->Count[v] };
  }
  int At(int v, int i) const { return this->Pool[this->Start[v] + i]; }
  int Size(int v) const { return this->Count[v]; }

  void Push(int v, int t)
  {
    if (this->Count[v] == this->Room[v])
    {
      const std::size_t moved = this->Pool.size();
      this->Pool.resize(moved + 2 * static_cast<std::size_t>(this->Room[v]) + 1, -1);
      std::copy_n(this->Pool.begin() + this->Start[v], this->Count[v], this->Pool.begin() + moved);
      this->Start[v] = moved;
      this->Room[v] = 2 * this->Room[v] + 1;
    }
    this->Pool[this->Start[v] + this->Count[v]++] = t;
  }

  /// Removes t from v's triangles, keeping the others' order.
  void Erase(int v, int t)
  {
    int* first = this->Pool.data() + this->Start[v];
    int* last = first + this->Count[v];
    int* at = std::find(first, last, t);
    std::copy(at + 1, last, at);
    --this->Count[v];
  }

  void Clear(int v) { this->Count[v] = 0; }

private:
  std::vector<int> Pool;
  std::vector<std::size_t> Start;
  std::vector<int> Count, Room;
};

// The mutable state of one simplification.
class EdgeCollapser
{
public:
  EdgeCollapser(const DecimationBlock& block, double maximumError, std::size_t maximumCollapses)
    : Points(block.Points)
    , Quadrics(block.Quadrics)
    , Triangles(block.Triangles)
    , Owned(block.Triangles.size())
    , MaximumCost(maximumError > 0.0 ? maximumError * maximumError : -1.0)
    , MaximumCollapses(maximumCollapses)
  {
    const std::size_t n = block.Ids.size();
    this->Triangles.insert(this->Triangles.end(), block.Halo.begin(), block.Halo.end());
    this->Star.Build(n, this->Triangles, 4);
    // Each triangle's normal before any collapse: no collapse may turn a triangle against it,
    // even in steps that each turn it less than a right angle.
    this->Initial.resize(this->Triangles.size());
    for (std::size_t t = 0; t < this->Triangles.size(); ++t)
    {
      const auto& tri = this->Triangles[t];
      Cross(this->Point(tri[0]), this->Point(tri[1]), this->Point(tri[2]), this->Initial[t].data());
    }
    this->Gone.assign(n, 0);
    this->Movable.assign(n, 0);
    this->Mark.assign(n, 0);
    for (std::size_t v = 0; v < n; ++v)
    {
      this->Movable[v] = !block.Fixed[v] && this->IsDisc(static_cast<int>(v));
    }
  }

  std::vector<Collapse> Run()
  {
    std::vector<Collapse> log;
    double level = 0.0;
    // A candidate found invalid is dropped: it is queued again only when one of its ends
    // changes (its cost changes then too).
    this->QueueAllEdges();
    while (!this->Queue.Empty() && log.size() < this->MaximumCollapses)
    {
      const Candidate c = this->Queue.Top();
      this->Queue.Pop();
      // Every candidate left costs at least this one.
      if (this->MaximumCost >= 0.0 && c.Cost > this->MaximumCost)
      {
        break;
      }
      const int a = c.A(), b = c.B();
      if (this->Gone[a] || this->Gone[b])
      {
        continue;
      }
      // An edge is queued again, with its new cost, whenever an end changes. A candidate whose
      // cost is no longer the edge's is stale; one whose cost is still the edge's has the same
      // key as the edge's current candidate, so taking it here is taking that one (the cost is
      // computed the same way, to the bit, each time).
      double position[3];
      if (this->Place(a, b, position) != c.Cost)
      {
        continue;
      }
      if (!this->CanCollapse(a, b, position))
      {
        continue;
      }
      this->CollapseEdge(a, b, position);
      level = std::max(level, c.Cost);
      log.push_back(Collapse{ b, a, { position[0], position[1], position[2] }, level });
      this->QueueEdgesAround(a);
    }
    return log;
  }

private:
  std::vector<double> Points;
  std::vector<Quadric> Quadrics;
  std::vector<std::array<int, 3>> Triangles; // own, then halo
  std::size_t Owned;
  double MaximumCost;
  std::size_t MaximumCollapses;
  TriangleStars Star;
  std::vector<std::array<double, 3>> Initial;
  std::vector<std::uint8_t> Gone, Movable;
  MinHeap<Candidate, Candidate::Cheaper> Queue;
  std::vector<int> NeighboursA; // scratch
  std::vector<unsigned> Mark;   // per vertex: the token of the last list it was put in
  unsigned Token = 0;

  const double* Point(int v) const { return this->Points.data() + 3 * v; }

  // Whether the triangles around v are all the block's own and form one closed fan.
  bool IsDisc(int v) const
  {
    const auto& star = this->Star[v];
    if (star.size() < 3)
    {
      return false;
    }
    std::vector<std::pair<int, int>> link; // (next, previous) corners around v
    for (int t : star)
    {
      if (static_cast<std::size_t>(t) >= this->Owned)
      {
        return false;
      }
      const auto& tri = this->Triangles[t];
      const int i = tri[0] == v ? 0 : (tri[1] == v ? 1 : 2);
      link.emplace_back(tri[(i + 1) % 3], tri[(i + 2) % 3]);
    }
    // One cycle: every corner starts exactly one link edge and ends exactly one, and walking
    // from the first comes back after all of them.
    std::size_t steps = 0;
    int at = link[0].second;
    do
    {
      int found = -1;
      for (std::size_t e = 0; e < link.size(); ++e)
      {
        if (link[e].first == at)
        {
          if (found >= 0)
          {
            return false;
          }
          found = static_cast<int>(e);
        }
      }
      if (found < 0)
      {
        return false;
      }
      at = link[found].second;
      ++steps;
    } while (at != link[0].second && steps <= link.size());
    return steps == link.size();
  }

  // A token no vertex is marked with yet.
  unsigned NextToken()
  {
    if (++this->Token == 0)
    {
      std::fill(this->Mark.begin(), this->Mark.end(), 0u);
      this->Token = 1;
    }
    return this->Token;
  }

  // The vertices of v's triangles but v, each once, in the order first met, marked with a new
  // token (a mark, not a sort: these lists are made several times a collapse).
  void Neighbours(int v, std::vector<int>& out)
  {
    out.clear();
    const unsigned token = this->NextToken();
    for (int t : this->Star[v])
    {
      for (int w : this->Triangles[t])
      {
        if (w != v && this->Mark[w] != token)
        {
          this->Mark[w] = token;
          out.push_back(w);
        }
      }
    }
  }

  Candidate Evaluate(int a, int b) const
  {
    double position[3];
    return Candidate(this->Place(a, b, position), a, b);
  }

  // The merged vertex of a and b: see PlaceCollapse.
  double Place(int a, int b, double position[3]) const
  {
    return PlaceCollapse(
      this->Quadrics[a] + this->Quadrics[b], this->Point(a), this->Point(b), position);
  }

  void QueueAllEdges()
  {
    for (std::size_t t = 0; t < this->Owned; ++t)
    {
      const auto& tri = this->Triangles[t];
      if (tri[0] == tri[1])
      {
        continue; // collapsed
      }
      for (int i = 0; i < 3; ++i)
      {
        const int p = tri[i], q = tri[(i + 1) % 3];
        // Each edge of a consistently oriented fan once: from its lower end.
        if (p < q && this->Movable[p] && this->Movable[q])
        {
          this->Queue.Push(this->Evaluate(p, q));
        }
      }
    }
  }

  void QueueEdgesAround(int v)
  {
    std::vector<int>& around = this->NeighboursA;
    this->Neighbours(v, around);
    for (int w : around)
    {
      if (this->Movable[w])
      {
        this->Queue.Push(v < w ? this->Evaluate(v, w) : this->Evaluate(w, v));
      }
    }
  }

  bool CanCollapse(int a, int b, const double position[3])
  {
    int opposite[2];
    if (!this->EdgeCorners(a, b, opposite) || !this->LinkConditionHolds(a, b))
    {
      return false;
    }
    // Each corner keeps at least three neighbours.
    if (this->Star.Size(opposite[0]) < 4 || this->Star.Size(opposite[1]) < 4)
    {
      return false;
    }
    return this->NoTriangleTurns(a, b, position);
  }

  // The third corners of the edge's two triangles; false unless it has exactly two, with
  // different corners.
  bool EdgeCorners(int a, int b, int opposite[2]) const
  {
    int shared = 0;
    for (int t : this->Star[a])
    {
      const auto& tri = this->Triangles[t];
      if (tri[0] == b || tri[1] == b || tri[2] == b)
      {
        if (shared == 2)
        {
          return false;
        }
        opposite[shared++] =
          tri[0] != a && tri[0] != b ? tri[0] : (tri[1] != a && tri[1] != b ? tri[1] : tri[2]);
      }
    }
    return shared == 2 && opposite[0] != opposite[1];
  }

  // The link condition: a and b have no common neighbour but the two corners.
  bool LinkConditionHolds(int a, int b)
  {
    // b's neighbours found among a's are marked anew, to be counted once (the token is taken
    // first: a token taken after a's list could clear its marks when the tokens wrap).
    const unsigned counted = this->NextToken();
    this->Neighbours(a, this->NeighboursA);
    const unsigned ofA = this->Token;
    int common = 0;
    for (int t : this->Star[b])
    {
      for (int w : this->Triangles[t])
      {
        if (w != b && this->Mark[w] == ofA)
        {
          this->Mark[w] = counted;
          ++common;
        }
      }
    }
    return common == 2;
  }

  // Whether no triangle that stays turns over or becomes degenerate when a and b merge at
  // `position`.
  bool NoTriangleTurns(int a, int b, const double position[3]) const
  {
    for (int end : { a, b })
    {
      for (int t : this->Star[end])
      {
        const auto& tri = this->Triangles[t];
        const bool both = (tri[0] == a || tri[1] == a || tri[2] == a) &&
          (tri[0] == b || tri[1] == b || tri[2] == b);
        if (both)
        {
          continue;
        }
        const double* p[3];
        const double* moved[3];
        for (int i = 0; i < 3; ++i)
        {
          p[i] = this->Point(tri[i]);
          moved[i] = tri[i] == end ? position : p[i];
        }
        double before[3], after[3];
        Cross(p[0], p[1], p[2], before);
        Cross(moved[0], moved[1], moved[2], after);
        const double* initial = this->Initial[t].data();
        const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
        const double fromStart =
          initial[0] * after[0] + initial[1] * after[1] + initial[2] * after[2];
        if (!(dot > 0.0) || !(fromStart > 0.0))
        {
          return false;
        }
      }
    }
    return true;
  }

  void CollapseEdge(int a, int b, const double position[3])
  {
    this->Quadrics[a] = this->Quadrics[a] + this->Quadrics[b];
    std::copy(position, position + 3, this->Points.begin() + 3 * a);
    // By place in b's star: pushing onto a's may move the pool.
    for (int i = 0; i < this->Star.Size(b); ++i)
    {
      const int t = this->Star.At(b, i);
      auto& tri = this->Triangles[t];
      if (tri[0] == a || tri[1] == a || tri[2] == a)
      {
        for (int w : tri)
        {
          if (w != b)
          {
            this->Star.Erase(w, t);
          }
        }
        tri = { -1, -1, -1 };
      }
      else
      {
        for (int& w : tri)
        {
          w = w == b ? a : w;
        }
        this->Star.Push(a, t);
      }
    }
    this->Star.Clear(b);
    this->Gone[b] = 1;
  }
};

} // namespace

void DecimationBlock::SortTriangles()
{
  for (auto* list : { &this->Triangles, &this->Halo })
  {
    for (auto& t : *list)
    {
      t = Rotated(t);
    }
    std::sort(list->begin(), list->end());
  }
  this->Halo.erase(std::unique(this->Halo.begin(), this->Halo.end()), this->Halo.end());
}

void DecimationBlock::ComputeQuadrics()
{
  const std::size_t n = this->Ids.size();
  this->Quadrics.assign(n, Quadric());
  std::vector<std::uint8_t> used(n, 0);
  for (const auto& t : this->Triangles)
  {
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  // Own and halo triangles merged in canonical order, so that a vertex seen by several blocks
  // gets the same sum in each.
  std::vector<std::array<int, 3>> all(this->Triangles);
  all.insert(all.end(), this->Halo.begin(), this->Halo.end());
  std::sort(all.begin(), all.end());
  for (const auto& t : all)
  {
    if (!used[t[0]] && !used[t[1]] && !used[t[2]])
    {
      continue;
    }
    const double* p = this->Points.data();
    const Quadric q =
      Quadric::OfTriangle(p + 3 * t[0], p + 3 * t[1], p + 3 * t[2], this->AreaWeighted);
    for (int v : t)
    {
      if (used[v])
      {
        this->Quadrics[v] = this->Quadrics[v] + q;
      }
    }
  }
}

std::vector<Collapse> Simplify(
  const DecimationBlock& block, double maximumError, std::size_t maximumCollapses)
{
  return EdgeCollapser(block, maximumError, maximumCollapses).Run();
}

void ApplyCollapses(DecimationBlock& block, const std::vector<Collapse>& log, std::size_t count)
{
  std::vector<int> into(block.Ids.size());
  for (std::size_t v = 0; v < into.size(); ++v)
  {
    into[v] = static_cast<int>(v);
  }
  for (std::size_t i = 0; i < count && i < log.size(); ++i)
  {
    const Collapse& c = log[i];
    block.Quadrics[c.Kept] = block.Quadrics[c.Kept] + block.Quadrics[c.Removed];
    std::copy(c.Position, c.Position + 3, block.Points.begin() + 3 * c.Kept);
    into[c.Removed] = c.Kept;
  }
  auto find = [&into](int v)
  {
    while (into[v] != v)
    {
      into[v] = into[into[v]];
      v = into[v];
    }
    return v;
  };
  std::size_t kept = 0;
  for (const auto& t : block.Triangles)
  {
    const std::array<int, 3> m = { find(t[0]), find(t[1]), find(t[2]) };
    if (m[0] != m[1] && m[1] != m[2] && m[0] != m[2])
    {
      block.Triangles[kept++] = m;
    }
  }
  block.Triangles.resize(kept);
}

} // namespace rgmc
