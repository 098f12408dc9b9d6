// Rank 0's decision over the component graph of all ranks (see rgmcComponentGraph.h).
#include "rgmcComponentGraph.h"

#include "rgmcUnionFind.h"

#include <array>

namespace rgmc
{

void Decide(Keep mode, const std::vector<std::int64_t>& parts,
  const std::vector<std::int64_t>& roots, const std::vector<std::int64_t>& edges, std::int64_t* out)
{
  const int numRanks = static_cast<int>(roots.size());
  std::vector<std::int64_t> first(numRanks + 1, 0); // dense number of each rank's first root
  for (int r = 0; r < numRanks; ++r)
  {
    first[r + 1] = first[r] + roots[r];
  }
  const std::int64_t total = first[numRanks];
  UnionFind<std::int64_t> sets;
  sets.Reset(static_cast<std::size_t>(total));
  struct Class
  {
    std::int64_t Triangles = 0;
    std::int64_t MinKey = std::numeric_limits<std::int64_t>::max();
    bool Seeded = false;
  };
  std::vector<Class> classes(static_cast<std::size_t>(total));
  const std::int64_t* at = parts.data();
  std::vector<std::array<std::int64_t, 3>> info(static_cast<std::size_t>(total));
  for (int r = 0; r < numRanks; ++r)
  {
    for (std::int64_t c = 0; c < roots[r]; ++c, at += 3)
    {
      info[first[r] + c] = { at[0], at[1], at[2] };
    }
    for (std::int64_t e = 0; e < edges[r]; ++e, at += 2)
    {
      auto dense = [&first](std::int64_t rc) { return first[rc >> 32] + (rc & 0xffffffff); };
      sets.Unite(dense(at[0]), dense(at[1]));
    }
  }
  for (std::int64_t c = 0; c < total; ++c)
  {
    Class& k = classes[sets.Find(c)];
    k.Triangles += info[c][0];
    k.MinKey = std::min(k.MinKey, info[c][1]);
    k.Seeded = k.Seeded || info[c][2] != 0;
  }
  std::vector<std::int64_t> selected;
  std::int64_t largest = -1;
  for (std::int64_t c = 0; c < total; ++c)
  {
    if (sets.Find(c) != c || classes[c].Triangles == 0)
    {
      continue;
    }
    if (mode == Keep::All || (mode == Keep::Seeded && classes[c].Seeded))
    {
      selected.push_back(c);
    }
    if (largest < 0 || classes[c].Triangles > classes[largest].Triangles ||
      (classes[c].Triangles == classes[largest].Triangles &&
        classes[c].MinKey < classes[largest].MinKey))
    {
      largest = c;
    }
  }
  if (mode == Keep::Largest && largest >= 0)
  {
    selected.push_back(largest);
  }
  std::sort(selected.begin(), selected.end(),
    [&classes](std::int64_t a, std::int64_t b) { return classes[a].MinKey < classes[b].MinKey; });
  std::vector<std::int64_t> idOfClass(static_cast<std::size_t>(total), -1);
  std::int64_t triangles = 0;
  for (std::size_t n = 0; n < selected.size(); ++n)
  {
    idOfClass[selected[n]] = static_cast<std::int64_t>(n);
    triangles += classes[selected[n]].Triangles;
  }
  std::int64_t* header = out;
  for (int r = 0; r < numRanks; ++r)
  {
    header[0] = 0;
    header[1] = triangles;
    header[2] = static_cast<std::int64_t>(selected.size());
    for (std::int64_t c = 0; c < roots[r]; ++c)
    {
      header[3 + c] = idOfClass[sets.Find(first[r] + c)];
    }
    header += 3 + roots[r];
  }
}

} // namespace rgmc
