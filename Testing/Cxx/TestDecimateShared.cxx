// Decimate Surface's shared vertices and its reading of the blocks' triangles on threads
// (rgmcDecimateShared.h, rgmcDecimateMessages.h) against plain serial versions of the same
// rules, on 1, 2, 16 and 64 threads: the records each rank is sent (as a set, to the rank of the
// vertex's id), the answers (to the word, in order), the blocks' lists and vertex records read
// from a message (in message order, after what the lists held), the triangles listed for each
// rank of a wave's blocks (ListSendings), and the same read from the rank's own part with no
// message (KeepTriangles) against the message, and the part's vertex table sorted out of place
// (SortDistinctGathered) against the in-place sort. The surfaces are large enough for many
// chunks, so vertices whose triangles or records straddle a chunk's end are met.
#include "rgmcCheck.h"
#include "rgmcDecimateMessages.h"
#include "rgmcDecimateShared.h"

#include "vtkCellArray.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

namespace
{

using rgmc::decimate::VertexBlocks;
using Record = std::array<vtkIdType, 3>; // (vertex id, vertex, block)

/// Triangles over `nv` vertices with shuffled global ids; the triangles' blocks in runs, so
/// that most vertices have one block and some several.
struct Soup
{
  vtkNew<vtkPolyData> Mesh;
  std::vector<std::int32_t> Blocks;

  Soup(vtkIdType nv, vtkIdType nt, std::mt19937_64& random)
  {
    vtkNew<vtkPoints> points;
    points->SetNumberOfPoints(nv);
    vtkNew<vtkIdTypeArray> ids;
    ids->SetNumberOfValues(nv);
    std::vector<vtkIdType> order(static_cast<std::size_t>(nv));
    for (vtkIdType v = 0; v < nv; ++v)
    {
      points->SetPoint(v, static_cast<double>(v), 0, 0);
      order[v] = 3 * v + 7; // ids neither dense nor in the vertices' order
    }
    std::shuffle(order.begin(), order.end(), random);
    for (vtkIdType v = 0; v < nv; ++v)
    {
      ids->SetValue(v, order[v]);
    }
    vtkNew<vtkCellArray> polys;
    std::int32_t block = 0;
    for (vtkIdType t = 0; t < nt; ++t)
    {
      // Corners near each other in index (as a real surface's are), now and then far.
      auto below = [&random](vtkIdType n) { return static_cast<vtkIdType>(random() % n); };
      const vtkIdType a = below(nv);
      const vtkIdType pts[3] = { a, (a + 1 + below(5)) % nv,
        below(50) == 0 ? below(nv) : (a + 2 + below(9)) % nv };
      polys->InsertNextCell(3, pts);
      block = random() % 1000 == 0 ? static_cast<std::int32_t>(random() % 40) : block;
      this->Blocks.push_back(block);
    }
    this->Mesh->SetPoints(points);
    this->Mesh->SetPolys(polys);
    this->Mesh->GetPointData()->SetGlobalIds(ids);
  }
};

std::set<Record> SerialRecords(
  const rgmc::decimate::SurfacePart& part, const std::vector<std::int32_t>& blocks)
{
  std::set<Record> records;
  for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
  {
    vtkIdType c[3];
    part.Corners(t, c);
    for (vtkIdType v : c)
    {
      records.insert({ part.Id(v), v, blocks[t] });
    }
  }
  return records;
}

void TestVertexBlocks()
{
  std::mt19937_64 random(5);
  Soup soup(150000, 250000, random);
  rgmc::decimate::SurfacePart part;
  part.Read(soup.Mesh);
  const std::set<Record> expected = SerialRecords(part, soup.Blocks);
  for (int threads : { 1, 2, 16, 64 })
  {
    for (std::size_t ranks : { 1, 3 })
    {
      VertexBlocks outgoing(ranks);
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]()
        {
          const rgmc::decimate::LowestBlocks lowest(part, soup.Blocks);
          rgmc::decimate::WriteVertexBlocks(
            part, lowest, OtherBlocks(part, soup.Blocks, lowest), outgoing);
        });
      std::set<Record> sent;
      std::size_t count = 0, misplaced = 0;
      for (std::size_t r = 0; r < ranks; ++r)
      {
        for (std::size_t at = 0; at + 2 < outgoing[r].size(); at += 3)
        {
          const Record record{ outgoing[r][at], outgoing[r][at + 1], outgoing[r][at + 2] };
          sent.insert(record);
          misplaced += static_cast<std::size_t>(record[0]) % ranks != r;
          ++count;
        }
      }
      RGMC_CHECK(sent == expected && count == expected.size(),
        "each (vertex, block) once: " << count << " records, " << sent.size() << " distinct, "
                                      << expected.size() << " expected, on " << threads
                                      << " threads, " << ranks << " ranks");
      RGMC_CHECK(misplaced == 0, misplaced << " records sent to another rank than the id's");
    }
  }
}

/// Records as three ranks would send them: vertices in one block or several, asked by one rank
/// or more, some records repeated.
VertexBlocks Asked(std::mt19937_64& random)
{
  VertexBlocks asked(3);
  for (vtkIdType id = 0; id < 120000; ++id)
  {
    const int records = 1 + static_cast<int>(random() % 6);
    for (int k = 0; k < records; ++k)
    {
      const vtkIdType rank = static_cast<vtkIdType>(random() % 3);
      const vtkIdType index = id * 10 + rank; // a rank's index of the vertex
      const vtkIdType block = static_cast<vtkIdType>(random() % (id % 4 == 0 ? 1 : 5));
      asked[rank].insert(asked[rank].end(), { 5 * id + 1, index, block });
    }
  }
  return asked;
}

VertexBlocks SerialAnswers(const VertexBlocks& asked)
{
  std::map<vtkIdType, std::pair<std::set<vtkIdType>, std::set<std::pair<vtkIdType, vtkIdType>>>>
    byId;
  for (std::size_t r = 0; r < asked.size(); ++r)
  {
    for (std::size_t at = 0; at + 2 < asked[r].size(); at += 3)
    {
      auto& entry = byId[asked[r][at]];
      entry.first.insert(asked[r][at + 2]);
      entry.second.insert({ static_cast<vtkIdType>(r), asked[r][at + 1] });
    }
  }
  VertexBlocks answers(asked.size());
  for (const auto& vertex : byId)
  {
    if (vertex.second.first.size() < 2)
    {
      continue;
    }
    for (const auto& asker : vertex.second.second)
    {
      for (vtkIdType block : vertex.second.first)
      {
        answers[asker.first].insert(answers[asker.first].end(), { asker.second, block });
      }
    }
  }
  return answers;
}

void TestAnswers()
{
  std::mt19937_64 random(9);
  const VertexBlocks asked = Asked(random);
  const VertexBlocks expected = SerialAnswers(asked);
  RGMC_CHECK(!expected[0].empty() && !expected[1].empty() && !expected[2].empty(),
    "every rank has answers to check");
  for (int threads : { 1, 2, 16, 64 })
  {
    VertexBlocks copy = asked, answers(asked.size());
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]() { rgmc::decimate::AnswerSharedVertices(rgmc::decimate::AskedRecords(copy), answers); });
    RGMC_CHECK(
      answers == expected, "the answers equal the serial ones on " << threads << " threads");
    RGMC_CHECK(copy[0].empty() && copy[2].empty(), "the records asked are let go");
  }
}

/// A message as WriteTriangles lays it out: own and halo triangles for blocks 10, 20, ..., then
/// vertex records (with quadrics when `quadrics`).
std::vector<vtkIdType> Message(std::mt19937_64& random, vtkIdType own, vtkIdType halo,
  std::size_t records, bool quadrics, int blocks)
{
  std::vector<vtkIdType> words{ own, halo };
  for (vtkIdType t = 0; t < own + halo; ++t)
  {
    const vtkIdType block = 10 * (1 + static_cast<vtkIdType>(random() % blocks));
    words.insert(words.end(),
      { block, static_cast<vtkIdType>(random() % 1000), static_cast<vtkIdType>(random() % 1000),
        t });
  }
  for (std::size_t i = 0; i < records * (quadrics ? 14 : 4); ++i)
  {
    words.push_back(static_cast<vtkIdType>(random() >> 2));
  }
  return words;
}

void TestReadTriangles()
{
  std::mt19937_64 random(3);
  for (bool quadrics : { false, true })
  {
    const int blocks = 37;
    const std::vector<vtkIdType> first = Message(random, 5, 3, 7, quadrics, blocks);
    const std::vector<vtkIdType> second = Message(random, 200000, 90000, 150000, quadrics, blocks);
    // The serial reading: each triangle appended to its list, each record after the others.
    std::vector<rgmc::decimate::Block> expected(blocks);
    for (int b = 0; b < blocks; ++b)
    {
      expected[b].Id = 10 * (b + 1);
    }
    std::vector<std::array<vtkIdType, 14>> expectedRecords;
    for (const auto* words : { &first, &second })
    {
      const vtkIdType n = (*words)[0] + (*words)[1];
      for (vtkIdType t = 0; t < n; ++t)
      {
        const vtkIdType* w = words->data() + 2 + 4 * t;
        auto& block = expected[static_cast<std::size_t>(w[0] / 10 - 1)];
        (t < (*words)[0] ? block.Own : block.Halo).push_back({ w[1], w[2], w[3] });
      }
      const std::size_t size = quadrics ? 14 : 4;
      for (std::size_t at = 2 + 4 * n; at + size <= words->size(); at += size)
      {
        std::array<vtkIdType, 14> record{};
        std::copy_n(words->data() + at, size, record.begin());
        expectedRecords.push_back(record);
      }
    }
    for (int threads : { 1, 2, 16, 64 })
    {
      std::vector<rgmc::decimate::Block> read(blocks);
      for (int b = 0; b < blocks; ++b)
      {
        read[b].Id = 10 * (b + 1);
      }
      rgmc::decimate::VertexTable table;
      table.HasQuadrics = quadrics;
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]()
        {
          rgmc::decimate::ReadTriangles(first, read, table);
          rgmc::decimate::ReadTriangles(second, read, table);
        });
      bool same = table.Vertices.size() == expectedRecords.size();
      for (int b = 0; same && b < blocks; ++b)
      {
        same = read[b].Own == expected[b].Own && read[b].Halo == expected[b].Halo;
      }
      for (std::size_t i = 0; same && i < expectedRecords.size(); ++i)
      {
        std::vector<vtkIdType> written(table.Words());
        table.Write(i, written.data());
        same = std::equal(written.begin(), written.end(), expectedRecords[i].begin());
      }
      RGMC_CHECK(same,
        "the lists and records read equal the serial reading on "
          << threads << " threads" << (quadrics ? ", with quadrics" : ""));
    }
  }
  // A triangle for a block the rank does not own.
  std::vector<rgmc::decimate::Block> some(2);
  some[0].Id = 10;
  some[1].Id = 30;
  rgmc::decimate::VertexTable table;
  bool refused = false;
  try
  {
    rgmc::decimate::ReadTriangles(Message(random, 100000, 0, 0, false, 3), some, table);
  }
  catch (const std::runtime_error&)
  {
    refused = true;
  }
  RGMC_CHECK(refused, "a triangle for a block not owned is an error");
}

/// Blocks 10, 20, ..., 10 * count, their lists holding what a first message brought.
std::vector<rgmc::decimate::Block> BlocksAfterAMessage(std::mt19937_64 random, int count)
{
  std::vector<rgmc::decimate::Block> blocks(static_cast<std::size_t>(count));
  for (int b = 0; b < count; ++b)
  {
    blocks[b].Id = 10 * (b + 1);
  }
  rgmc::decimate::VertexTable none;
  rgmc::decimate::ReadTriangles(Message(random, 3000, 1000, 0, false, count), blocks, none);
  return blocks;
}

/// Whether two vertex tables hold the same records, word for word, in the same order.
bool SameRecords(const rgmc::decimate::VertexTable& one, const rgmc::decimate::VertexTable& other)
{
  bool same = one.Vertices.size() == other.Vertices.size() &&
    one.Quadrics.size() == other.Quadrics.size() && one.Words() == other.Words();
  std::vector<vtkIdType> a(one.Words()), b(other.Words());
  for (std::size_t i = 0; same && i < one.Vertices.size(); ++i)
  {
    one.Write(i, a.data());
    other.Write(i, b.data());
    same = a == b;
  }
  return same;
}

/// SortDistinctGathered against SortDistinct: the same records, word for word, for tables with
/// copies of records (equal, as a vertex's copies are), with and without quadrics, and with
/// negative ids (which the packed sort cannot take); on 1, 2, 16 and 64 threads.
void TestSortDistinctGathered()
{
  std::mt19937_64 random(29);
  for (int flavour : { 0, 1, 2 }) // without quadrics; with; negative ids
  {
    rgmc::decimate::VertexTable table;
    table.HasQuadrics = flavour != 0;
    std::vector<rgmc::decimate::Vertex> distinct(100000);
    std::vector<rgmc::Quadric> terms(distinct.size());
    for (std::size_t i = 0; i < distinct.size(); ++i)
    {
      distinct[i].Id = static_cast<vtkIdType>(random() % 1000000000) * (flavour == 2 ? -1 : 1);
      for (double& x : distinct[i].Point)
      {
        x = static_cast<double>(random() % 100000) / 3.0;
      }
      for (double& t : terms[i].Terms)
      {
        t = static_cast<double>(random() % 100000) / 7.0;
      }
    }
    for (int k = 0; k < 250000; ++k) // each record once or more, in no order
    {
      const std::size_t i = k < 100000 ? static_cast<std::size_t>(k) : random() % distinct.size();
      table.Add(distinct[i], &terms[i]);
    }
    for (std::size_t i = table.Vertices.size() - 1; i > 0; --i)
    {
      const std::size_t j = random() % (i + 1);
      std::swap(table.Vertices[i], table.Vertices[j]);
      if (table.HasQuadrics)
      {
        std::swap(table.Quadrics[i], table.Quadrics[j]);
      }
    }
    rgmc::decimate::VertexTable expected = table;
    expected.SortDistinct();
    for (int threads : { 1, 2, 16, 64 })
    {
      rgmc::decimate::VertexTable gathered = table;
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]() { gathered.SortDistinctGathered(); });
      RGMC_CHECK(SameRecords(gathered, expected),
        "SortDistinctGathered equals SortDistinct, flavour " << flavour << ", " << threads
                                                             << " threads");
    }
  }
}

/// ListSendings against the serial loop it stands for: per rank, the triangles whose block is
/// in the wave (in triangle order), then each triangle's other blocks of the wave through its
/// shared vertices (in triangle order, then block order, each block once); for each of three
/// waves on 3 ranks, with vertices in up to 3 other blocks, on 1, 2, 16 and 64 threads.
void TestListSendings()
{
  std::mt19937_64 random(23);
  Soup soup(150000, 250000, random);
  rgmc::decimate::SurfacePart part;
  part.Read(soup.Mesh);
  const int blocks = 40, ranks = 3, waves = 3;
  std::vector<int> waveOf(blocks), owner(blocks);
  for (int b = 0; b < blocks; ++b)
  {
    waveOf[b] = static_cast<int>(random() % waves);
    owner[b] = static_cast<int>(random() % ranks);
  }
  std::vector<std::uint32_t> sharedFirst(part.NumberOfVertices() + 1, 0);
  std::vector<std::int32_t> sharedBlocks;
  for (std::size_t v = 0; v < part.NumberOfVertices(); ++v)
  {
    for (int k = static_cast<int>(random() % 8); k < 3; ++k) // none for most vertices
    {
      sharedBlocks.push_back(static_cast<std::int32_t>(random() % blocks));
    }
    sharedFirst[v + 1] = static_cast<std::uint32_t>(sharedBlocks.size());
  }
  const rgmc::decimate::TriangleRoutes routes{ soup.Blocks.data(), waveOf.data(), owner.data(),
    sharedFirst.data(), sharedBlocks.data() };
  for (int wave = 0; wave < waves; ++wave)
  {
    std::vector<std::vector<rgmc::decimate::Sending>> own(ranks), halo(ranks);
    for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
    {
      const vtkIdType block = soup.Blocks[t], tri = static_cast<vtkIdType>(t);
      if (waveOf[block] == wave)
      {
        own[owner[block]].push_back({ block, tri, 0 });
      }
      vtkIdType c[3];
      part.Corners(t, c);
      std::set<vtkIdType> others;
      for (vtkIdType v : c)
      {
        for (std::uint32_t i = sharedFirst[v]; i < sharedFirst[v + 1]; ++i)
        {
          if (sharedBlocks[i] != block && waveOf[sharedBlocks[i]] == wave)
          {
            others.insert(sharedBlocks[i]);
          }
        }
      }
      for (vtkIdType other : others)
      {
        halo[owner[other]].push_back({ other, tri, 1 });
      }
    }
    for (int threads : { 1, 2, 16, 64 })
    {
      std::vector<rgmc::decimate::Sendings> going;
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]() { going = rgmc::decimate::ListSendings(part, routes, wave, ranks); });
      bool same = going.size() == static_cast<std::size_t>(ranks);
      for (int r = 0; same && r < ranks; ++r)
      {
        std::vector<rgmc::decimate::Sending> expected = own[r];
        expected.insert(expected.end(), halo[r].begin(), halo[r].end());
        same = std::equal(going[r].begin(), going[r].end(), expected.begin(), expected.end()) &&
          !expected.empty();
      }
      RGMC_CHECK(same,
        "the sendings of wave " << wave << " equal the serial loop's on " << threads << " threads");
    }
  }
}

/// KeepTriangles against the message it stands for, ReadTriangles(WriteTriangles(...)): the
/// blocks' lists (after what they held) and the records, word for word and in the same order
/// (by id) for a part read from the input and for one of its own with quadrics; with negative
/// ids (which the packed sort cannot take) the same records once the table is sorted. On 1, 2,
/// 16 and 64 threads.
void TestKeepTriangles()
{
  using rgmc::decimate::Sending;
  std::mt19937_64 random(17);
  const int count = 40;
  for (int flavour : { 0, 1, 2 }) // the input; negative ids; the part's own, with quadrics
  {
    Soup soup(150000, 250000, random);
    auto* ids = vtkIdTypeArray::SafeDownCast(soup.Mesh->GetPointData()->GetGlobalIds());
    for (vtkIdType v = 0; flavour == 1 && v < ids->GetNumberOfValues(); ++v)
    {
      ids->SetValue(v, -ids->GetValue(v));
    }
    rgmc::decimate::SurfacePart part;
    part.Read(soup.Mesh);
    if (flavour == 2)
    {
      part.OwnInput();
      part.Vertices.HasQuadrics = true;
      part.Vertices.Quadrics.resize(part.Vertices.Vertices.size());
      for (auto& q : part.Vertices.Quadrics)
      {
        for (double& term : q)
        {
          term = static_cast<double>(random() % 100000) / 7.0;
        }
      }
    }
    // As ListSendings lists them: by triangle, its own block and some halos.
    rgmc::decimate::Sendings staying;
    for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
    {
      const vtkIdType own = 10 * (1 + soup.Blocks[t]);
      if (random() % 3 != 0)
      {
        staying.push_back({ own, static_cast<vtkIdType>(t), 0 });
      }
      if (random() % 10 == 0)
      {
        staying.push_back(
          { 10 * (1 + static_cast<vtkIdType>(random() % count)), static_cast<vtkIdType>(t), 1 });
      }
    }
    // Each rank's list holds the own ones first, as ListSendings lists them.
    std::stable_partition(
      staying.begin(), staying.end(), [](const rgmc::decimate::Sending& s) { return s[2] == 0; });
    const std::mt19937_64 first = random;
    std::vector<rgmc::decimate::Block> expected = BlocksAfterAMessage(first, count);
    rgmc::decimate::VertexTable expectedTable;
    expectedTable.HasQuadrics = part.HasQuadrics();
    std::vector<vtkIdType> words;
    rgmc::decimate::WriteTriangles(words, staying, part);
    const auto halos = std::count_if(
      staying.begin(), staying.end(), [](const rgmc::decimate::Sending& s) { return s[2] != 0; });
    RGMC_CHECK(words[1] == halos && words[0] + words[1] == static_cast<vtkIdType>(staying.size()),
      "the message counts " << words[0] << " own and " << words[1] << " halo triangles, not "
                            << staying.size() - halos << " and " << halos);
    rgmc::decimate::ReadTriangles(words, expected, expectedTable);
    if (flavour == 1)
    {
      expectedTable.SortDistinct();
    }
    for (int threads : { 1, 2, 16, 64 })
    {
      std::vector<rgmc::decimate::Block> kept = BlocksAfterAMessage(first, count);
      rgmc::decimate::VertexTable table;
      table.HasQuadrics = part.HasQuadrics();
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]() { rgmc::decimate::KeepTriangles(staying, part, kept, table); });
      if (flavour == 1)
      {
        table.SortDistinct();
      }
      bool lists = true;
      for (int b = 0; lists && b < count; ++b)
      {
        lists = kept[b].Own == expected[b].Own && kept[b].Halo == expected[b].Halo;
      }
      RGMC_CHECK(lists,
        "the lists kept equal the message's, flavour " << flavour << ", " << threads << " threads");
      RGMC_CHECK(SameRecords(table, expectedTable),
        "the records kept equal the message's, flavour " << flavour << ", " << threads
                                                         << " threads");
    }
  }
}

} // namespace

int main()
{
  TestVertexBlocks();
  TestAnswers();
  TestReadTriangles();
  TestSortDistinctGathered();
  TestListSendings();
  TestKeepTriangles();
  return rgmc_test::Result("TestDecimateShared");
}
