/* jkr/dt: a chunked arena for the per-atom contact rows (fix_jkr_dt_contacts.h).

   Each atom's row (its partners' IDs, its contacts' values) is one segment
   taken from the arena; a row that must grow takes a new segment and leaves
   its old one behind. Nothing is freed segment by segment: the store builds a
   fresh arena, tight, whenever it rewrites every row (to_rows) and drops the
   old one, so the memory follows the contacts, not the largest row times the
   atoms.                                                                    */

#ifndef JKR_DT_ARENA_H
#define JKR_DT_ARENA_H

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

namespace JKRDT {

template <typename T> class Arena {
 public:
  // n contiguous elements, uninitialised (n > 0)
  T *take(std::size_t n)
  {
    if (chunks.empty() || used + n > size.back()) {
      const std::size_t s = std::max(n, CHUNK);
      chunks.emplace_back(new T[s]);
      size.push_back(s);
      used = 0;
    }
    T *p = chunks.back().get() + used;
    used += n;
    return p;
  }
  std::size_t bytes() const
  {
    std::size_t n = 0;
    for (std::size_t s : size) n += s;
    return n * sizeof(T);
  }
  void swap(Arena &other)
  {
    chunks.swap(other.chunks);
    size.swap(other.size);
    std::swap(used, other.used);
  }
  void clear()
  {
    chunks.clear();
    size.clear();
    used = 0;
  }

 private:
  static constexpr std::size_t CHUNK = 1 << 16;    // elements per chunk
  std::vector<std::unique_ptr<T[]>> chunks;
  std::vector<std::size_t> size;
  std::size_t used = 0;
};

}    // namespace JKRDT

#endif
