/* jkr/dt: per-contact state storage. See fix_jkr_dt_contacts.h. */

#include "fix_jkr_dt_contacts.h"

#include "pair_jkr_dt.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "memory.h"

#include <algorithm>
#include <utility>
#include <vector>
#include <cstring>

using namespace LAMMPS_NS;

static constexpr int INITIAL_CAPACITY = 8;

/* ---------------------------------------------------------------------- */

FixJKRDTContacts::FixJKRDTContacts(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), npartner(nullptr), partner(nullptr), values(nullptr), ledger(nullptr),
    owner(nullptr),
    dnum(0), mask(0), maxpartner(INITIAL_CAPACITY), nmax_alloc(0)
{
  if (narg != 4)
    error->all(FLERR,
               "fix jkr/dt/contacts is created by pair_style jkr/dt; do not define it by hand");
  mask = utils::inumeric(FLERR, arg[3], false, lmp);
  dnum = layout_size(mask, field_offset);

  restart_peratom = 1;
  create_attribute = 1;
  peratom_flag = 1;
  size_peratom_cols = NLEDGER;
  peratom_freq = 1;
  scalar_flag = 1;
  global_freq = 1;
  extscalar = 0;

  grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
}

/* ---------------------------------------------------------------------- */

FixJKRDTContacts::~FixJKRDTContacts()
{
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(npartner);
  memory->destroy(partner);
  memory->destroy(values);
  memory->destroy(ledger);
  memory->destroy(owner);
}

/* ----------------------------------------------------------------------
   between runs: atom IDs renumbered under the stored contacts are refused;
   contacts whose partner was deleted are removed (called by the pair style)
------------------------------------------------------------------------- */

void FixJKRDTContacts::check_atoms(bigint natoms_before)
{
  int renumbered = 0;
  for (int i = 0; i < atom->nlocal; i++)
    if (npartner[i] > 0 && owner[i] != atom->tag[i]) renumbered++;
  int any = 0;
  MPI_Allreduce(&renumbered, &any, 1, MPI_INT, MPI_SUM, world);
  if (any)
    error->all(FLERR,
               "pair jkr/dt: the IDs of {} atoms with contacts changed since the contacts were "
               "stored (delete_atoms ... compress yes, reset_atoms id, ...), so each contact "
               "would point at another grain. Delete with 'delete_atoms ... compress no', and "
               "renumber only before the first run",
               any);
  if (natoms_before <= 0 || atom->natoms >= natoms_before) return;

  // atoms were deleted: every rank learns the IDs that remain
  std::vector<tagint> ids = gather(std::vector<tagint>(atom->tag, atom->tag + atom->nlocal),
                                   world);
  std::sort(ids.begin(), ids.end());

  // ... and every stored (atom, partner) pair: each contact is stored with both atoms, so
  // a pair whose partner exists but does not store it back was renumbered, not deleted
  std::vector<tagint> mine_edges;
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < npartner[i]; k++) {
      mine_edges.push_back(atom->tag[i]);
      mine_edges.push_back(partner[i][k]);
    }
  const std::vector<tagint> flat = gather(mine_edges, world);
  std::vector<std::pair<tagint, tagint>> edges;
  for (size_t e = 0; e < flat.size(); e += 2) edges.emplace_back(flat[e], flat[e + 1]);
  std::sort(edges.begin(), edges.end());

  bigint mine = 0, removed = 0;
  int lonely = 0, anylonely = 0;
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = npartner[i] - 1; k >= 0; k--) {
      const tagint t = partner[i][k];
      if (!std::binary_search(ids.begin(), ids.end(), t)) {
        remove(i, k);
        mine++;
      } else if (!std::binary_search(edges.begin(), edges.end(),
                                     std::make_pair(t, atom->tag[i]))) {
        lonely++;
      }
    }
  MPI_Allreduce(&lonely, &anylonely, 1, MPI_INT, MPI_SUM, world);
  if (anylonely)
    error->all(FLERR,
               "pair jkr/dt: after delete_atoms, {} stored contacts point at atoms that do not "
               "store them back: the atom IDs were renumbered (delete_atoms ... compress yes), "
               "so each contact would point at another grain. Delete with 'delete_atoms ... "
               "compress no'",
               anylonely);
  MPI_Allreduce(&mine, &removed, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  if (removed && comm->me == 0)
    utils::logmesg(lmp, "pair jkr/dt: {} contacts with deleted atoms removed\n", removed);
}

/* ----------------------------------------------------------------------
   a run without pair jkr/dt would move the atoms under stored contacts
------------------------------------------------------------------------- */

void FixJKRDTContacts::init()
{
  if (force->pair_match("jkr/dt", 1, 0)) return;
  const bigint stored = count();
  if (stored > 0)
    error->all(FLERR,
               "pair jkr/dt: the pair style is now {}, but {} bonded contacts of jkr/dt are "
               "stored; a run without jkr/dt would leave them stale. Keep pair_style jkr/dt "
               "(use pair_style hybrid/overlay to add another), or 'unfix {}' to drop them",
               force->pair_style ? force->pair_style : "none", stored, id);
}

bigint FixJKRDTContacts::count() const
{
  bigint mine = 0, all = 0;
  for (int i = 0; i < atom->nlocal; i++) mine += npartner[i];
  MPI_Allreduce(&mine, &all, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  return all / 2;    // each contact is stored with both of its atoms
}

std::vector<tagint> FixJKRDTContacts::gather(const std::vector<tagint> &mine, MPI_Comm world)
{
  int nprocs = 1;
  MPI_Comm_size(world, &nprocs);
  const int n = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  for (int r = 1; r < nprocs; r++) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<tagint> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_LMP_TAGINT, all.data(), counts.data(), displs.data(),
                 MPI_LMP_TAGINT, world);
  return all;
}

/* ----------------------------------------------------------------------
   end of a run: the pair style reports how well the step resolved contacts
------------------------------------------------------------------------- */

void FixJKRDTContacts::post_run()
{
  auto *pair = dynamic_cast<PairJKRDT *>(force->pair_match("jkr/dt", 1, 0));
  if (pair) pair->report_run();
}

/* ----------------------------------------------------------------------
   offsets of the fields present in a layout mask; returns doubles per contact
------------------------------------------------------------------------- */

int FixJKRDTContacts::layout_size(int layout, int *offsets)
{
  int n = 0;
  for (int f = 0; f < NFIELD; f++) {
    offsets[f] = -1;
    if ((layout >> f) & 1) {
      offsets[f] = n;
      n += FIELD_SIZE[f];
    }
  }
  return n;
}

/* ----------------------------------------------------------------------
   switch to a new set of fields, keeping the values of fields in both
------------------------------------------------------------------------- */

void FixJKRDTContacts::set_layout(int newmask)
{
  if (newmask == mask) return;
  int newoffset[NFIELD];
  const int newdnum = layout_size(newmask, newoffset);
  const int nmax = nmax_alloc;

  double **newvalues = nullptr;
  if (newdnum > 0) memory->create(newvalues, nmax, maxpartner * newdnum, "jkr/dt:values");
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < npartner[i]; k++) {
      double *dst = newvalues ? newvalues[i] + k * newdnum : nullptr;
      if (dst) std::fill(dst, dst + newdnum, 0.0);
      for (int f = 0; f < NFIELD; f++)
        if (newoffset[f] >= 0 && field_offset[f] >= 0)
          std::copy_n(values[i] + k * dnum + field_offset[f], FIELD_SIZE[f], dst + newoffset[f]);
    }
  memory->destroy(values);
  values = newvalues;
  mask = newmask;
  dnum = newdnum;
  std::copy_n(newoffset, NFIELD, field_offset);
}

/* ----------------------------------------------------------------------
   look-up, insertion and removal of the contacts of atom i
------------------------------------------------------------------------- */

int FixJKRDTContacts::find(int i, tagint partner_tag) const
{
  const tagint *row = partner[i];
  for (int k = 0; k < npartner[i]; k++)
    if (row[k] == partner_tag) return k;
  return -1;
}

double *FixJKRDTContacts::add(int i, tagint partner_tag)
{
  if (npartner[i] == maxpartner) grow_partner_capacity(maxpartner + 1);
  owner[i] = atom->tag[i];
  const int k = npartner[i]++;
  partner[i][k] = partner_tag;
  if (dnum == 0) return nullptr;
  double *v = values[i] + k * dnum;
  std::fill(v, v + dnum, 0.0);
  return v;
}

void FixJKRDTContacts::remove(int i, int k)
{
  const int last = --npartner[i];
  if (k == last) return;
  partner[i][k] = partner[i][last];
  if (dnum) std::copy_n(values[i] + last * dnum, dnum, values[i] + k * dnum);
}

/* ----------------------------------------------------------------------
   a rank's per-atom capacity grows whenever one atom needs more room;
   it never drops a contact
------------------------------------------------------------------------- */

void FixJKRDTContacts::grow_partner_capacity(int needed)
{
  if (needed <= maxpartner) return;
  const int newmax = std::max(needed, maxpartner + maxpartner / 2);
  const int nmax = nmax_alloc;

  tagint **newpartner = nullptr;
  double **newvalues = nullptr;
  memory->create(newpartner, nmax, newmax, "jkr/dt:partner");
  if (dnum) memory->create(newvalues, nmax, newmax * dnum, "jkr/dt:values");
  for (int i = 0; i < nmax; i++) {
    std::copy_n(partner[i], npartner[i], newpartner[i]);
    if (dnum) std::copy_n(values[i], npartner[i] * dnum, newvalues[i]);
  }
  memory->destroy(partner);
  memory->destroy(values);
  partner = newpartner;
  values = newvalues;
  maxpartner = newmax;
}

/* ----------------------------------------------------------------------
   per-atom callbacks: growth, copy (sorting, deletion), new atoms
------------------------------------------------------------------------- */

void FixJKRDTContacts::grow_arrays(int nmax)
{
  const int oldmax = nmax_alloc;
  memory->grow(npartner, nmax, "jkr/dt:npartner");
  memory->grow(partner, nmax, maxpartner, "jkr/dt:partner");
  if (dnum) memory->grow(values, nmax, maxpartner * dnum, "jkr/dt:values");
  memory->grow(ledger, nmax, NLEDGER, "jkr/dt:ledger");
  memory->grow(owner, nmax, "jkr/dt:owner");
  nmax_alloc = nmax;
  for (int i = oldmax; i < nmax; i++) set_arrays(i);
  array_atom = ledger;
}

void FixJKRDTContacts::copy_arrays(int i, int j, int /*delflag*/)
{
  npartner[j] = npartner[i];
  std::copy_n(partner[i], npartner[i], partner[j]);
  if (dnum) std::copy_n(values[i], npartner[i] * dnum, values[j]);
  std::copy_n(ledger[i], (int) NLEDGER, ledger[j]);
  owner[j] = owner[i];
}

void FixJKRDTContacts::set_arrays(int i)
{
  npartner[i] = 0;
  owner[i] = 0;
  std::fill(ledger[i], ledger[i] + NLEDGER, 0.0);
}

/* ----------------------------------------------------------------------
   migration between ranks: count, partner IDs, values, ledger, owner ID
------------------------------------------------------------------------- */

int FixJKRDTContacts::pack_exchange(int i, double *buf)
{
  int m = 0;
  buf[m++] = npartner[i];
  for (int k = 0; k < npartner[i]; k++) buf[m++] = ubuf(partner[i][k]).d;
  for (int k = 0; k < npartner[i] * dnum; k++) buf[m++] = values[i][k];
  for (int l = 0; l < NLEDGER; l++) buf[m++] = ledger[i][l];
  buf[m++] = ubuf(owner[i]).d;
  return m;
}

int FixJKRDTContacts::unpack_exchange(int nlocal, double *buf)
{
  int m = 0;
  const int n = static_cast<int>(buf[m++]);
  grow_partner_capacity(n);
  npartner[nlocal] = n;
  for (int k = 0; k < n; k++) partner[nlocal][k] = (tagint) ubuf(buf[m++]).i;
  for (int k = 0; k < n * dnum; k++) values[nlocal][k] = buf[m++];
  for (int l = 0; l < NLEDGER; l++) ledger[nlocal][l] = buf[m++];
  owner[nlocal] = (tagint) ubuf(buf[m++]).i;
  return m;
}

/* ----------------------------------------------------------------------
   restart: size, layout mask, count, partner IDs, values, ledger, owner ID.
   The mask lets a run read a file written with other fields switched on.
------------------------------------------------------------------------- */

int FixJKRDTContacts::pack_restart(int i, double *buf)
{
  int m = 1;
  buf[m++] = mask;
  m += pack_exchange(i, &buf[m]);
  buf[0] = m;
  return m;
}

void FixJKRDTContacts::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[nlocal][m]);
  const double *buf = extra[nlocal] + m + 1;

  const int filemask = static_cast<int>(*buf++);
  int fileoffset[NFIELD];
  const int filednum = layout_size(filemask, fileoffset);
  const int n = static_cast<int>(*buf++);
  grow_partner_capacity(n);
  npartner[nlocal] = n;
  for (int k = 0; k < n; k++) partner[nlocal][k] = (tagint) ubuf(*buf++).i;
  for (int k = 0; k < n; k++, buf += filednum) {
    if (!dnum) continue;
    double *dst = values[nlocal] + k * dnum;
    std::fill(dst, dst + dnum, 0.0);
    for (int f = 0; f < NFIELD; f++)
      if (field_offset[f] >= 0 && fileoffset[f] >= 0)
        std::copy_n(buf + fileoffset[f], FIELD_SIZE[f], dst + field_offset[f]);
  }
  for (int l = 0; l < NLEDGER; l++) ledger[nlocal][l] = *buf++;
  owner[nlocal] = (tagint) ubuf(*buf++).i;
}

int FixJKRDTContacts::size_restart(int i)
{
  return 4 + npartner[i] * (1 + dnum) + NLEDGER;
}

// called on every rank by write_restart, so it may reduce over ranks
int FixJKRDTContacts::maxsize_restart()
{
  int nmine = 0, nall = 0;
  for (int i = 0; i < atom->nlocal; i++) nmine = std::max(nmine, npartner[i]);
  MPI_Allreduce(&nmine, &nall, 1, MPI_INT, MPI_MAX, world);
  return 4 + nall * (1 + dnum) + NLEDGER;    // as size_restart()
}

/* ---------------------------------------------------------------------- */

double FixJKRDTContacts::memory_usage()
{
  const double nmax = nmax_alloc;
  return nmax *
      (sizeof(int) + maxpartner * (sizeof(tagint) + dnum * sizeof(double)) +
       NLEDGER * sizeof(double));
}
