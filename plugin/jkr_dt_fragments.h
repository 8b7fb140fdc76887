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
};

}    // namespace LAMMPS_NS

#endif
