/* jkr/dt: the departure rule of fix jkr/dt/settle (depart yes|shadow).

   A fragment has left the collision for good when nothing can reach it
   again. Grains interact only by contact, so bodies move on straight lines
   between contacts. Each fragment is taken as a body with centre of mass c,
   velocity V, a bounding radius R (the farthest grain surface from c) and an
   internal speed u: the largest speed of a grain against the rigid motion
   V + omega x (x - c) that fits the fragment's angular momentum
   (I omega = L). A grain's distance from c grows at most at u (the rotation
   moves it along its sphere). Fragment j departs when it is quiet,
   u_j < sqrt(E_break / m) (no grain of it moves fast enough against the
   others to break a contact, so it sheds nothing), it is not the largest
   fragment (the remnant the settle rule watches), and against every other
   fragment i that has not departed either

     the two bounding spheres, on their straight lines and growing at
     u_i + u_j, never come within a grain diameter of each other; or
     i's sphere as it is now, and every grain of i that has the energy to
     break free (1/2 m u^2 above E_break times its contacts) on its own
     straight line, never come within a grain diameter of j's sphere
     growing at u_j

   (the second lets a small fragment leave a hot remnant: its bound grains
   stay inside it, and its fast free ones fly elsewhere). never_meet() is
   the exact least distance of a point and a growing sphere on straight
   lines. The rule is exact for bodies that are
   rigid or slower inside than u; it can be wrong when a fragment heats up
   after the check (a later collision inside it). How often, is measured
   with depart shadow against runs that keep every fragment moving
   (validation/departure.py).                                              */

#include "fix_jkr_dt_settle_depart.h"

#include "fix_jkr_dt_contacts.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "force.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

using namespace LAMMPS_NS;

namespace {

// one fragment as a moving body
struct Body {
  double m = 0.0, c[3] = {0, 0, 0}, V[3] = {0, 0, 0};
  double R = 0.0, u = 0.0;
  tagint label = 0;    // smallest atom ID
  bigint n = 0;        // grains
  bool departed = false;
};

// omega from I omega = L (point masses about the centre of mass); a body that is
// a line (a dimer) has no inertia about its axis and no spin about it is fitted
void fit_rotation(const double I[6], const double L[3], double w[3])
{
  // I = [xx yy zz xy xz yz]
  const double tr = I[0] + I[1] + I[2];
  const double eps = 1e-12 * tr;
  const double a = I[0] + eps, b = I[1] + eps, c = I[2] + eps, d = I[3], e = I[4], f = I[5];
  const double A = b * c - f * f, B = e * f - d * c, C = d * f - b * e;
  const double det = a * A + d * B + e * C;
  if (!(tr > 0.0) || !(std::fabs(det) > 1e-30 * tr * tr * tr)) {
    w[0] = w[1] = w[2] = 0.0;
    return;
  }
  const double D = a * c - e * e, E = d * e - a * f, F = a * b - d * d;
  w[0] = (A * L[0] + B * L[1] + C * L[2]) / det;
  w[1] = (B * L[0] + D * L[1] + E * L[2]) / det;
  w[2] = (C * L[0] + E * L[1] + F * L[2]) / det;
}

// whether a point at p moving at q (both relative to a sphere's centre) stays farther
// than reach from it for all t >= 0 while the sphere's radius grows at u: the least of
// |p + q t| - u t is b sqrt(1 - k^2) - k a, with k = u / |q|, a the distance still to
// travel to the closest approach and b the miss distance, unless that least is now
// (then it is |p|)
bool never_meet(const double p[3], const double q[3], double reach, double u)
{
  const double pp = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  if (!(pp > reach)) return false;
  const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  if (!(qn > u)) return false;    // the sphere grows faster than the point moves
  const double k = u / qn;
  const double a = -(p[0] * q[0] + p[1] * q[1] + p[2] * q[2]) / qn;
  const double b = std::sqrt(std::max(0.0, pp * pp - a * a));
  const double root = std::sqrt(1.0 - k * k);
  if (-k * b / root > a) return true;    // the least is now: they only draw apart
  return b * root - k * a > reach;
}

}    // namespace

// what a check knows of its fragments, step by step
struct SettleDeparture::Census {
  int M = 0;                             // fragments with contacts (union-find roots)
  std::vector<int> body_of_node;         // per graph node: its fragment
  std::vector<int> body;                 // per owned grain: its fragment, or -1 (single)
  std::vector<double> xu;                // per owned grain: its unwrapped position
  std::vector<double> single;            // this rank's single grains: ID, m, x, v, r, departed
  std::vector<Body> B;                   // the fragments with contacts, then single grains
  std::vector<double> internal_speed2;   // per owned grain: |v - rigid motion|^2
  std::vector<int> first_grain;          // the hot grains of fragment b: first_grain[b] ...
  std::vector<double> grains;            // ... of x, v, r (7 values each), every rank's
  double rmax = 0.0;                     // the largest grain radius, every rank's
};

bool SettleDeparture::find(FragmentGraph &graph, const int *npartner, double now)
{
  Census c;
  number_bodies(c, graph);
  sum_motion(c, graph);
  fit_spin_and_reach(c);
  gather_hot_grains(c, npartner);
  add_single_grains(c);
  return depart(c, who_leaves(c), now);
}

// fragments with contacts: the union-find roots, numbered in node order
void SettleDeparture::number_bodies(Census &c, FragmentGraph &graph) const
{
  const int nlocal = atom->nlocal;
  const tagint *tag = atom->tag;
  c.body_of_node.assign(graph.parent.size(), -1);
  for (int k = 0; k < (int) graph.parent.size(); k++) {
    const int r = graph.root(k);
    if (c.body_of_node[r] < 0) c.body_of_node[r] = c.M++;
    c.body_of_node[k] = c.body_of_node[r];
  }
  c.body.assign(nlocal, -1);
  c.xu.resize(3 * (size_t) nlocal);
  for (int i = 0; i < nlocal; i++) {
    auto it = graph.index.find(tag[i]);
    if (it != graph.index.end()) c.body[i] = c.body_of_node[it->second];
    domain->unmap(atom->x[i], atom->image[i], &c.xu[3 * i]);
  }
}

// pass 1: mass, centre of mass, velocity, departed grains; smallest ID
void SettleDeparture::sum_motion(Census &c, const FragmentGraph &graph) const
{
  const int nlocal = atom->nlocal, M = c.M;
  const int *mask = atom->mask;
  const tagint *tag = atom->tag;
  const double *rmass = atom->rmass, *radius = atom->radius;
  double **v = atom->v;
  std::vector<double> sum(8 * (size_t) M, 0.0), all(8 * (size_t) M);
  std::vector<tagint> label(M, MAXTAGINT), label_all(M);
  // single grains travel to every rank whole: ID, m, x, v, r, departed
  for (int i = 0; i < nlocal; i++) {
    const double m = rmass[i];
    const double *x = &c.xu[3 * i];
    const int b = c.body[i];
    if (b < 0) {
      c.single.insert(c.single.end(), {(double) tag[i], m, x[0], x[1], x[2], v[i][0], v[i][1],
                                       v[i][2], radius[i], (mask[i] & departed_bit) ? 1.0 : 0.0});
      continue;
    }
    double *s = &sum[8 * b];
    s[0] += m;
    for (int k = 0; k < 3; k++) {
      s[1 + k] += m * x[k];
      s[4 + k] += m * v[i][k];
    }
    if (mask[i] & departed_bit) s[7] += 1.0;
    label[b] = std::min(label[b], tag[i]);
  }
  MPI_Allreduce(sum.data(), all.data(), 8 * M, MPI_DOUBLE, MPI_SUM, world);
  MPI_Allreduce(label.data(), label_all.data(), M, MPI_LMP_TAGINT, MPI_MIN, world);

  c.B.assign(M, Body());
  std::vector<int> node_count(M, 0);
  for (int k = 0; k < (int) graph.parent.size(); k++) node_count[c.body_of_node[k]]++;
  for (int b = 0; b < M; b++) {
    const double *s = &all[8 * b];
    Body &B = c.B[b];
    B.m = s[0];
    for (int k = 0; k < 3; k++) {
      B.c[k] = s[1 + k] / s[0];
      B.V[k] = s[4 + k] / s[0];
    }
    B.departed = s[7] > 0.0;
    B.label = label_all[b];
    B.n = node_count[b];
  }
}

// pass 2: inertia tensor and angular momentum about the centre of mass, the spin;
// pass 3: bounding radius and internal speed
void SettleDeparture::fit_spin_and_reach(Census &c) const
{
  const int nlocal = atom->nlocal, M = c.M;
  const double *rmass = atom->rmass, *radius = atom->radius;
  double **v = atom->v;
  const std::vector<double> &xu = c.xu;
  std::vector<Body> &B = c.B;
  std::vector<double> rot(9 * (size_t) M, 0.0), rot_all(9 * (size_t) M);
  for (int i = 0; i < nlocal; i++) {
    const int b = c.body[i];
    if (b < 0) continue;
    const double m = rmass[i];
    const double r[3] = {xu[3 * i] - B[b].c[0], xu[3 * i + 1] - B[b].c[1],
                         xu[3 * i + 2] - B[b].c[2]};
    const double w[3] = {v[i][0] - B[b].V[0], v[i][1] - B[b].V[1], v[i][2] - B[b].V[2]};
    double *s = &rot[9 * b];
    s[0] += m * (r[1] * r[1] + r[2] * r[2]);
    s[1] += m * (r[0] * r[0] + r[2] * r[2]);
    s[2] += m * (r[0] * r[0] + r[1] * r[1]);
    s[3] -= m * r[0] * r[1];
    s[4] -= m * r[0] * r[2];
    s[5] -= m * r[1] * r[2];
    s[6] += m * (r[1] * w[2] - r[2] * w[1]);
    s[7] += m * (r[2] * w[0] - r[0] * w[2]);
    s[8] += m * (r[0] * w[1] - r[1] * w[0]);
  }
  MPI_Allreduce(rot.data(), rot_all.data(), 9 * M, MPI_DOUBLE, MPI_SUM, world);
  std::vector<double> omega(3 * (size_t) M);
  for (int b = 0; b < M; b++) fit_rotation(&rot_all[9 * b], &rot_all[9 * b + 6], &omega[3 * b]);

  std::vector<double> ext(2 * (size_t) M, 0.0), ext_all(2 * (size_t) M);
  c.internal_speed2.assign(nlocal, 0.0);
  for (int i = 0; i < nlocal; i++) {
    const int b = c.body[i];
    if (b < 0) continue;
    const double *w = &omega[3 * b];
    const double r[3] = {xu[3 * i] - B[b].c[0], xu[3 * i + 1] - B[b].c[1],
                         xu[3 * i + 2] - B[b].c[2]};
    const double rigid[3] = {w[1] * r[2] - w[2] * r[1], w[2] * r[0] - w[0] * r[2],
                             w[0] * r[1] - w[1] * r[0]};
    double u2 = 0.0;
    for (int k = 0; k < 3; k++) {
      const double d = v[i][k] - B[b].V[k] - rigid[k];
      u2 += d * d;
    }
    const double reach = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) + radius[i];
    ext[2 * b] = std::max(ext[2 * b], reach);
    ext[2 * b + 1] = std::max(ext[2 * b + 1], std::sqrt(u2));
    c.internal_speed2[i] = u2;
  }
  MPI_Allreduce(ext.data(), ext_all.data(), 2 * M, MPI_DOUBLE, MPI_MAX, world);
  for (int b = 0; b < M; b++) {
    B[b].R = ext_all[2 * b];
    B[b].u = ext_all[2 * b + 1];
  }
}

// the grains of fragments with contacts that have the energy to break free, every
// rank's, grouped by fragment: x, v, r. A grain whose kinetic energy against its
// fragment's rigid motion is below E_break per contact it holds cannot break them
// all: it stays bound, inside its fragment's sphere
void SettleDeparture::gather_hot_grains(Census &c, const int *npartner) const
{
  const int nlocal = atom->nlocal, M = c.M;
  const double *rmass = atom->rmass, *radius = atom->radius;
  double **v = atom->v;
  std::vector<double> mine_grains;
  for (int i = 0; i < nlocal; i++) {
    const int b = c.body[i];
    if (b < 0 || c.B[b].departed) continue;
    if (0.5 * rmass[i] * c.internal_speed2[i] <= npartner[i] * break_energy) continue;
    const double *x = &c.xu[3 * i];
    mine_grains.insert(mine_grains.end(),
                       {(double) b, x[0], x[1], x[2], v[i][0], v[i][1], v[i][2], radius[i]});
  }
  const std::vector<double> grains_raw = FixJKRDTContacts::gather(mine_grains, world);
  c.first_grain.assign(M + 1, 0);
  for (size_t k = 0; k < grains_raw.size(); k += 8) c.first_grain[(int) grains_raw[k] + 1]++;
  for (int b = 0; b < M; b++) c.first_grain[b + 1] += c.first_grain[b];
  c.grains.resize(grains_raw.size() / 8 * 7);
  std::vector<int> fill(c.first_grain.begin(), c.first_grain.end() - 1);
  for (size_t k = 0; k < grains_raw.size(); k += 8)
    std::copy(&grains_raw[k + 1], &grains_raw[k + 8], &c.grains[7 * fill[(int) grains_raw[k]]++]);
}

// single grains of every rank, in rank order, as bodies after the fragments
void SettleDeparture::add_single_grains(Census &c) const
{
  const std::vector<double> singles = FixJKRDTContacts::gather(c.single, world);
  double rmax = 0.0;
  for (int i = 0; i < atom->nlocal; i++) rmax = std::max(rmax, atom->radius[i]);
  MPI_Allreduce(&rmax, &c.rmax, 1, MPI_DOUBLE, MPI_MAX, world);
  for (size_t k = 0; k < singles.size(); k += 10) {
    Body s;
    s.label = static_cast<tagint>(singles[k]);
    s.m = singles[k + 1];
    for (int d = 0; d < 3; d++) {
      s.c[d] = singles[k + 2 + d];
      s.V[d] = singles[k + 5 + d];
    }
    s.R = singles[k + 8];
    s.departed = singles[k + 9] > 0.0;
    s.n = 1;
    c.B.push_back(s);
  }
}

// per body, 1 if it leaves: the largest fragment stays; the others are tested,
// candidates shared out over ranks
std::vector<int> SettleDeparture::who_leaves(const Census &c) const
{
  const std::vector<Body> &B = c.B;
  const int F = static_cast<int>(B.size()), M = c.M;
  int largest = -1;
  for (int b = 0; b < F; b++)
    if (largest < 0 || B[b].n > B[largest].n ||
        (B[b].n == B[largest].n && B[b].label < B[largest].label))
      largest = b;
  std::vector<int> active;
  for (int b = 0; b < F; b++)
    if (!B[b].departed) active.push_back(b);
  const double margin = 2.0 * c.rmax;
  std::vector<int> leaves(F, 0), leaves_all(F, 0), hot;
  for (size_t a = comm->me; a < active.size(); a += comm->nprocs) {
    const Body &J = B[active[a]];
    if (active[a] == largest || !(J.u < quiet_speed)) continue;
    // the spheres first, for all (cheap); the grains of hot fragments only if they pass
    bool free = true;
    hot.clear();
    for (const int i : active) {
      if (i == active[a]) continue;
      const Body &I = B[i];
      const double p[3] = {I.c[0] - J.c[0], I.c[1] - J.c[1], I.c[2] - J.c[2]};
      const double q[3] = {I.V[0] - J.V[0], I.V[1] - J.V[1], I.V[2] - J.V[2]};
      // both bounding spheres growing at their internal speeds never meet ...
      if (never_meet(p, q, I.R + J.R + margin, I.u + J.u)) continue;
      // ... or I's sphere as it is now, and each of its grains on its own line, never
      // meet J's growing sphere (a hot fragment whose fast grains fly elsewhere)
      if (i < M && I.u > 0.0 && never_meet(p, q, I.R + J.R + margin, J.u)) {
        hot.push_back(i);
        continue;
      }
      free = false;
      break;
    }
    for (size_t h = 0; free && h < hot.size(); h++) {
      const int i = hot[h];
      for (int g = c.first_grain[i]; free && g < c.first_grain[i + 1]; g++) {
        const double *G = &c.grains[7 * g];
        const double pg[3] = {G[0] - J.c[0], G[1] - J.c[1], G[2] - J.c[2]};
        const double qg[3] = {G[3] - J.V[0], G[4] - J.V[1], G[5] - J.V[2]};
        free = never_meet(pg, qg, G[6] + J.R + margin, J.u);
      }
    }
    if (free) leaves[active[a]] = 1;
  }
  MPI_Allreduce(leaves.data(), leaves_all.data(), F, MPI_INT, MPI_MAX, world);
  return leaves_all;
}

// counts, the log, and for depart yes the grains' groups
bool SettleDeparture::depart(const Census &c, const std::vector<int> &leaves_all, double now)
{
  const std::vector<Body> &B = c.B;
  const int F = static_cast<int>(B.size()), M = c.M;
  const int nlocal = atom->nlocal;
  int *mask = atom->mask;
  const tagint *tag = atom->tag;
  bigint n_frag = 0, n_grains = 0;
  double gone_grains = 0.0, gone_frags = 0.0;
  for (int b = 0; b < F; b++) {
    if (B[b].departed) {
      gone_grains += B[b].n;
      gone_frags += 1;
    }
    if (!leaves_all[b]) continue;
    n_frag++;
    n_grains += B[b].n;
    if (mode == SHADOW && shadowed.insert(B[b].label).second && comm->me == 0)
      utils::logmesg(lmp, "jkr/dt/settle: would depart step {} label {} size {}\n",
                     update->ntimestep, B[b].label, B[b].n);
  }
  if (mode != YES) return false;
  departed_grains = gone_grains + n_grains;
  departed_fragments = gone_frags + n_frag;
  if (n_frag == 0) return false;
  // grains of fragments with contacts by their body; single grains by their ID
  std::unordered_map<tagint, int> single_leaves;
  for (int b = M; b < F; b++)
    if (leaves_all[b]) single_leaves.emplace(B[b].label, b);
  // the time of departure, where the deck keeps it (fix property/atom d_departed_at), so
  // that a picture can draw a departed grain where it flies at a later time
  int flag, cols;
  const int slot = atom->find_custom(DEPARTED_AT, flag, cols);
  double *departed_at = (slot >= 0 && flag == 1 && cols == 0) ? atom->dvector[slot] : nullptr;
  for (int i = 0; i < nlocal; i++) {
    const bool go =
        c.body[i] >= 0 ? leaves_all[c.body[i]] != 0 : single_leaves.count(tag[i]) > 0;
    if (!go) continue;
    mask[i] |= departed_bit;
    mask[i] &= ~moving_bits;
    if (departed_at) departed_at[i] = now;
  }
  if (comm->me == 0)
    utils::logmesg(lmp,
                   "jkr/dt/settle: departed step {} fragments {} grains {} (so far {} "
                   "fragments, {} grains)\n",
                   update->ntimestep, n_frag, n_grains, departed_fragments, departed_grains);
  return true;
}
