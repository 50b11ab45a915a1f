// The facet counts hull completion keeps: how many simplices (found or
// added) hold each facet on the growing boundary of the completed complex.
//
// Open-addressing hash tables (linear probing, power-of-two capacity, at
// most half full) of D ascending ids and a count, in 64 shards chosen by the
// hash's top bits. Completion adds several facets per added simplex between
// its parallel rounds: the ordered map it used first cost 0.24 s of the 0.7 s
// completion of a 1M uniform input, and one serial table later cost a cache
// miss per facet (a 32 MB table; round 0 of 1M points at 40% skipped cells:
// 0.05 s serial, 0.03 s now).
// bump_all() adds a round's facets shard by shard in parallel, each shard's
// table small enough to stay in cache while its facets go in.
//
// Written here rather than taken from a library because the Debian-packaged
// hash tables (std::unordered_map; absl's flat_hash_map would add a
// dependency for this one use; TBB's concurrent maps lock or allocate per
// entry) are node-based or heavy, and this table needs only
// insert-or-increment and lookup on keys that never leave.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>

#include "point_buckets.hpp"

namespace tessera::front {

template <int D>
class FacetTable {
 public:
  using Facet = std::array<std::int32_t, D>;  ///< ids >= 0, ascending

  explicit FacetTable(std::size_t expected = 0) {
    for (Shard& s : shards_) s.rehash(capacity_for(expected / kShards));
  }

  /// Add one simplex's hold on f; returns f's count after it.
  int bump(const Facet& f) {
    const std::uint64_t h = hash(f);
    return shards_[h >> kShardShift].bump(f, h);
  }

  /// f's count (0: never added).
  int count(const Facet& f) const {
    const std::uint64_t h = hash(f);
    return shards_[h >> kShardShift].count(f, h);
  }

  /// bump() on facet(i) for every i < m (m < 2^32), in parallel (call it
  /// within the caller's task arena); count_after[i] is then facet(i)'s
  /// count once all are in, at most 255. Counts do not depend on the order
  /// of the bumps, so nothing here depends on the thread count.
  template <class FacetOf>
  void bump_all(std::size_t m, FacetOf&& facet, std::vector<std::uint8_t>& count_after) {
    // The items gathered by shard, each with its facet, so that a shard
    // streams through its own (bucket_rows: a parallel counting sort).
    struct Entry {
      Facet f;
      std::uint32_t item;
    };
    std::vector<std::int64_t> begin;
    std::vector<Entry> entries;
    bucket_rows(
        kShards, m, [](std::size_t) { return 1; }, [&](std::size_t i, std::size_t) { return hash(facet(i)) >> kShardShift; },
        [&](std::size_t i, std::size_t) { return Entry{facet(i), static_cast<std::uint32_t>(i)}; }, begin, entries);
    count_after.resize(m);
    tbb::parallel_for(std::size_t{0}, kShards, [&](std::size_t k) {
      Shard& s = shards_[k];
      const auto first = static_cast<std::size_t>(begin[k]), last = static_cast<std::size_t>(begin[k + 1]);
      for (std::size_t e = first; e < last; ++e) s.bump(entries[e].f, hash(entries[e].f));
      for (std::size_t e = first; e < last; ++e)
        count_after[entries[e].item] = static_cast<std::uint8_t>(std::min(255, s.count(entries[e].f, hash(entries[e].f))));
    });
  }

 private:
  static constexpr std::size_t kShards = 64;
  static constexpr int kShardShift = 58;  // the hash's top 6 bits pick the shard

  struct Slot {
    Facet key;
    int count = 0;  // 0: empty
  };

  // One shard: slots chosen by the hash's low bits.
  struct Shard {
    std::vector<Slot> slots;
    std::size_t size = 0;

    int bump(const Facet& f, std::uint64_t h) {
      if (2 * (size + 1) > slots.size()) rehash(2 * slots.size());
      Slot& s = slots[slot_of(f, h)];
      if (s.count == 0) {
        s.key = f;
        ++size;
      }
      return ++s.count;
    }

    int count(const Facet& f, std::uint64_t h) const { return slots[slot_of(f, h)].count; }

    // The slot holding f, or the empty slot where it would go (the table is
    // never full, so there is one).
    std::size_t slot_of(const Facet& f, std::uint64_t h) const {
      const std::size_t mask = slots.size() - 1;
      for (std::size_t k = h & mask;; k = (k + 1) & mask) {
        const Slot& s = slots[k];
        if (s.count == 0 || same(s.key, f)) return k;
      }
    }

    void rehash(std::size_t capacity) {
      std::vector<Slot> old(capacity);
      old.swap(slots);
      for (const Slot& s : old)
        if (s.count != 0) slots[slot_of(s.key, hash(s.key))] = s;
    }
  };

  // Key equality id by id: std::array's == calls memcmp for these few bytes.
  static bool same(const Facet& a, const Facet& b) {
    bool eq = true;
    for (int d = 0; d < D; ++d) eq &= a[static_cast<std::size_t>(d)] == b[static_cast<std::size_t>(d)];
    return eq;
  }

  static std::size_t capacity_for(std::size_t n) {
    std::size_t c = 16;
    while (c < 2 * n) c *= 2;
    return c;
  }

  static std::uint64_t hash(const Facet& f) {
    // Multiply-xorshift over the ids (a splitmix64-style finaliser).
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::int32_t id : f) {
      h ^= static_cast<std::uint32_t>(id);
      h *= 0xBF58476D1CE4E5B9ull;
      h ^= h >> 31;
    }
    return h;
  }

  std::array<Shard, kShards> shards_;
};

}  // namespace tessera::front
