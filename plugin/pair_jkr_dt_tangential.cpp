/* jkr/dt: a tangential channel switched off between runs. The tangential
   physics of a step is in jkr_dt_contact.h (tangential_step), its
   equations in jkr_dt_tangential.h.                                        */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"

#include "atom.h"
#include "error.h"

#include <cmath>

using namespace LAMMPS_NS;
using namespace JKRDT;
using Contacts = FixJKRDTContacts;

/* ----------------------------------------------------------------------
   a channel switched off between runs (pair_coeff ... frictionless): the
   energy its springs hold, eqs. (11), (21), (25) with the constants of the
   last run (kept by the contact fix, so that this holds across a pair_style
   command too),
   leaves pe and goes to the channel's ledger, half to each atom of the
   contact, so that ke + erotate + pe + dissipated stays what it was
------------------------------------------------------------------------- */

void PairJKRDT::book_channels_switched_off(const std::vector<Param> &fresh, Contacts &C)
{
  double **x = atom->x;
  const tagint *tag = atom->tag;
  const int *type = atom->type;
  const std::vector<Param> last = made_with_params(C.made_with);
  if (last.size() != fresh.size()) return;    // no run yet, or other atom types
  int unseen = 0;
  bool any_off = false;
  for (size_t k = 0; k < fresh.size(); k++)
    any_off = any_off || (last[k].sliding && !fresh[k].sliding) ||
        (last[k].rolling && !fresh[k].rolling) || (last[k].twisting && !fresh[k].twisting);
  if (!any_off) return;
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < C.npartner[i]; k++) {
      const int j = (atom->map_style != Atom::MAP_NONE) ? atom->map(C.partner[i][k]) : -1;
      if (j < 0) {
        unseen++;
        continue;
      }
      const Param &before = last[type[i] * nstride + type[j]];
      const Param &after = fresh[type[i] * nstride + type[j]];
      const bool off[NCHANNEL] = {before.sliding && !after.sliding,
                                  before.rolling && !after.rolling,
                                  before.twisting && !after.twisting};
      if (!(off[0] || off[1] || off[2])) continue;
      ContactState c;
      if (!load_state(C.contact_values(i, k), C.layout(), c)) continue;    // never traced
      const int p = (tag[i] < tag[j]) ? i : j, q = (p == i) ? j : i;
      const V3 d12 = vec(x[p]) - vec(x[q]);
      const double dist = norm(d12);
      const ContactConstants K = contact_constants(before, atom->radius[p], atom->radius[q]);
      ChannelLoad load[NCHANNEL];
      tangential_load(c, (1.0 / dist) * d12, 1.0 / dist, K.r1, K.r2, K.S.R, K.K, load);
      for (int ch = 0; ch < NCHANNEL; ch++)
        if (off[ch]) C.ledger[i][LOSS_TANGENTIAL + ch] += 0.5 * load[ch].U;
    }
  int any = 0;
  MPI_Allreduce(&unseen, &any, 1, MPI_INT, MPI_SUM, world);
  if (any)
    error->all(FLERR,
               "pair jkr/dt: a channel was switched off, but {} contact partners are not "
               "found to book the energy its springs hold; add 'atom_modify map array' before "
               "the box is defined",
               any);
}
