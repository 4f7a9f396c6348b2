// A small open-addressing hash map (linear probing, power-of-two capacity, no erase) for the
// recombination's hot lookups: one flat array instead of std::unordered_map's node per entry
// (a cache miss and an allocation each). Insertion keeps the first value of a key, like
// std::unordered_map::emplace.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hexfem {

// Murmur3's 64-bit finalizer: every input bit reaches the low bits used as the slot index.
inline std::uint64_t mix64(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  h ^= h >> 33;
  return h;
}

struct NoValue {};

template <class Key, class Value, class Hash>
class OpenHashMap {
 public:
  explicit OpenHashMap(std::size_t expected = 0) { reserve(expected); }

  void reserve(std::size_t n) {
    std::size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    if (cap > slots_.size()) rehash(cap);
  }
  std::size_t size() const { return size_; }

  // Inserts key -> value unless key is present; returns true when inserted.
  bool emplace(const Key& key, const Value& value) {
    if (2 * (size_ + 1) > slots_.size()) rehash(slots_.size() * 2);
    Slot* s = probe(key);
    if (s->full) return false;
    *s = {key, value, true};
    ++size_;
    return true;
  }
  // The value of key, or nullptr.
  const Value* find(const Key& key) const {
    const Slot* s = probe(key);
    return s->full ? &s->value : nullptr;
  }
  bool contains(const Key& key) const { return probe(key)->full; }

 private:
  struct Slot {
    Key key{};
    Value value{};
    bool full = false;
  };

  Slot* probe(const Key& key) const {
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = static_cast<std::size_t>(Hash{}(key)) & mask;
    while (slots_[i].full && !(slots_[i].key == key)) i = (i + 1) & mask;
    return const_cast<Slot*>(&slots_[i]);
  }
  void rehash(std::size_t cap) {
    std::vector<Slot> old(cap);
    old.swap(slots_);
    size_ = 0;
    for (const Slot& s : old)
      if (s.full) *probe(s.key) = s, ++size_;
  }

  std::vector<Slot> slots_ = std::vector<Slot>(16);
  std::size_t size_ = 0;
};

template <class Key, class Hash>
class OpenHashSet {
 public:
  explicit OpenHashSet(std::size_t expected = 0) : map_(expected) {}
  bool insert(const Key& key) { return map_.emplace(key, NoValue{}); }
  bool contains(const Key& key) const { return map_.contains(key); }
  std::size_t size() const { return map_.size(); }
  void reserve(std::size_t n) { map_.reserve(n); }

 private:
  OpenHashMap<Key, NoValue, Hash> map_;
};

struct U64Hash {
  std::size_t operator()(std::uint64_t k) const { return static_cast<std::size_t>(mix64(k)); }
};

}  // namespace hexfem
