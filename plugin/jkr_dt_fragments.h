/* jkr/dt: the fragments of a collision as fix jkr/dt/settle finds them at a
   check: the connected components of the bonded-contact graph of all ranks,
   by union-find, the same on every rank. Atoms without contacts are not
   nodes: they are single grains.                                            */

#ifndef JKR_DT_FRAGMENTS_H
#define JKR_DT_FRAGMENTS_H

#include "lmptype.h"

#include <unordered_map>
#include <vector>

namespace LAMMPS_NS {

struct FragmentGraph {
  std::unordered_map<tagint, int> index;    // atom ID -> node
  std::vector<int> parent, size;            // union-find by size
  std::vector<tagint> edges;                // the bonded contacts, as pairs of atom IDs
  int root(int k)
  {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  }
  // the largest fragment's root: of fragments equally large, the one holding the smallest
  // atom ID; -1 where no atom has a contact (every fragment is one grain)
  int largest()
  {
    const int nodes = static_cast<int>(parent.size());
    std::vector<tagint> smallest(nodes, -1);
    for (const auto &entry : index) {
      const int r = root(entry.second);
      if (smallest[r] < 0 || entry.first < smallest[r]) smallest[r] = entry.first;
    }
    int best = -1;
    for (int k = 0; k < nodes; k++)
      if (parent[k] == k && (best < 0 || size[k] > size[best] ||
                             (size[k] == size[best] && smallest[k] < smallest[best])))
        best = k;
    return best;
  }
};

}    // namespace LAMMPS_NS

#endif
