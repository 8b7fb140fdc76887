/* jkr/dt: one step of a contact's tangential state (section 2.2): trace
   the pointers, integrate the twisting angle, clamp to the elastic limits,
   book the dissipated energy. The equations are in jkr_dt_tangential.h.

   Order within a step (after the drift of velocity Verlet, omega at its
   half-step value):
     1. the pointers turn with their particles: n <- turned(n, omega dt);
        phi += (omega1 - omega2) . n_c dt, with n_c at the half step
     2. a contact that breaks books what its springs held and is gone
     3. displacements beyond their limits are clamped (eqs. 42, A8)
     4. the loads (eqs. 14, 17, 23, 27) are computed from the clamped state
   A contact that forms gets n1 = -n_c, n2 = n_c, phi = 0. The force
   evaluation of a run's setup moves nothing and books nothing.

   Energy: a step that clamps or breaks books, per channel, the difference
   between the work the loads did (trapezoid over the step, which is what
   velocity Verlet gives the kinetic energy) and the change of the channel's
   potential; see step_dissipation(). The state at the start of the step is
   the stored one, at positions x - v dt.                                    */

#include "pair_jkr_dt.h"

#include "fix_jkr_dt_contacts.h"

#include "atom.h"
#include "error.h"
#include "update.h"

#include <cmath>

using namespace LAMMPS_NS;
using namespace JKRDT;
using Contacts = FixJKRDTContacts;

static constexpr int CHANNEL_LEDGER[NCHANNEL] = {Contacts::SLIDING, Contacts::ROLLING,
                                                 Contacts::TWISTING};

/* ----------------------------------------------------------------------
   stiffnesses and limits of one contact from the pair's constants
------------------------------------------------------------------------- */

Tangential PairJKRDT::tangential_constants(const Param &P, const NormalScales &S) const
{
  Tangential K;
  K.sliding = P.sliding;
  K.rolling = P.rolling;
  K.twisting = P.twisting;
  K.k_s = P.ks_coef * S.a0;                        // eq. (12)
  K.zeta_crit = P.zeta_coef * S.a0;                // eq. (36)
  K.k_r = P.k_r;                                   // eq. (22)
  K.xi_crit = P.xi_crit;
  K.k_t = P.kt_coef * S.a0 * S.a0 * S.a0;          // eq. (26)
  K.phi_crit = JKRDT::phi_crit();                  // eq. (38)
  return K;
}

/* ----------------------------------------------------------------------
   the stored state of a contact; false if its pointers were never set
   (a contact that was formed while no channel needed them)
------------------------------------------------------------------------- */

bool PairJKRDT::read_state(const double *values, ContactState &c) const
{
  const auto &C = *fix_contacts;
  c.n1 = {0.0, 0.0, 0.0};
  c.n2 = c.n1;
  c.phi = 0.0;
  bool set = true;
  if (C.has_field(Contacts::POINTERS)) {
    const double *n = values + C.offset(Contacts::POINTERS);
    c.n1 = vec(n);
    c.n2 = vec(n + 3);
    set = dot(c.n1, c.n1) > 0.0;
  }
  if (C.has_field(Contacts::TWIST)) c.phi = values[C.offset(Contacts::TWIST)];
  return set;
}

void PairJKRDT::write_state(double *values, const ContactState &c) const
{
  if (!values) return;
  const auto &C = *fix_contacts;
  if (C.has_field(Contacts::POINTERS)) {
    double *n = values + C.offset(Contacts::POINTERS);
    store(c.n1, n);
    store(c.n2, n + 3);
  }
  if (C.has_field(Contacts::TWIST)) values[C.offset(Contacts::TWIST)] = c.phi;
}

/* ----------------------------------------------------------------------
   advance the tangential state of contact p-q (p = particle 1) by a step;
   d12 = x1 - x2, dist = |d12|; fills the loads to apply (all zero for a
   contact that breaks)
------------------------------------------------------------------------- */

void PairJKRDT::tangential_step(int p, int q, const Param &P, const NormalScales &S,
                                double *state, bool formed, bool breaking,
                                const V3 &d12, double dist, ChannelLoad load[NCHANNEL])
{
  double **v = atom->v;
  double **omega = atom->omega;
  const double r1 = atom->radius[p], r2 = atom->radius[q];
  const bool setup = update->setupflag;
  const double dt = update->dt;
  const Tangential K = tangential_constants(P, S);
  const V3 nc = (1.0 / dist) * d12;    // eq. (9)

  ContactState before;
  const bool traced = !formed && read_state(state, before);
  ContactState now = before;
  if (!traced) {
    now = {-nc, nc, 0.0};    // section 2.2.4: n1(t0) = -n_c(t0), n2 = n_c
  } else if (!setup) {
    now.n1 = turned(before.n1, dt * vec(omega[p]));
    now.n2 = turned(before.n2, dt * vec(omega[q]));
    if (K.twisting) {
      // eq. (24): phi += (omega1 - omega2) . n_c dt, n_c at the half step:
      // (d12 - h) / |d12 - h| with h = (v1 - v2) dt/2, to first order in h / dist
      // (the error, (h / dist)^2 of one increment, is third order in dt)
      const V3 h = (0.5 * dt) * (vec(v[p]) - vec(v[q]));
      const V3 nc_half = ((1.0 + dot(nc, h) / dist) / dist) * (d12 - h);
      now.phi += dt * dot(vec(omega[p]) - vec(omega[q]), nc_half);
    }
  }

  const bool book_step = traced && !setup;
  int clamped = 0;
  if (!breaking) clamped = clamp_to_elastic_limits(now, nc, r1, r2, S.R, K);
  if (breaking)
    for (int ch = 0; ch < NCHANNEL; ch++) load[ch] = {0.0, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  else
    tangential_load(now, nc, dist, r1, r2, S.R, K, load);

  if (book_step && (breaking || clamped)) {
    const V3 dx12 = dt * (vec(v[p]) - vec(v[q]));
    const V3 dtheta1 = dt * vec(omega[p]), dtheta2 = dt * vec(omega[q]);
    ChannelLoad prev[NCHANNEL];
    const V3 d12_before = d12 - dx12;
    const double dist_before = norm(d12_before);
    tangential_load(before, (1.0 / dist_before) * d12_before, dist_before, r1, r2, S.R, K, prev);
    const int nlocal = atom->nlocal;
    for (int ch = 0; ch < NCHANNEL; ch++) {
      const double w_before = channel_work(prev[ch], dx12, dtheta1, dtheta2);
      const double w_after = channel_work(load[ch], dx12, dtheta1, dtheta2);
      book(CHANNEL_LEDGER[ch], step_dissipation(prev[ch].U, w_before, load[ch].U, w_after), p,
           q, nlocal);
    }
  }
  if (!breaking) write_state(state, now);
}

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
  const std::vector<Param> &last = C.made_with;
  if (last.size() != fresh.size()) return;    // no run yet
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
      if (!read_state(C.contact_values(i, k), c)) continue;    // never traced: no energy
      const int p = (tag[i] < tag[j]) ? i : j, q = (p == i) ? j : i;
      const V3 d12 = vec(x[p]) - vec(x[q]);
      const double dist = norm(d12);
      const NormalScales S = normal_scales(atom->radius[p], atom->radius[q], before.gamma,
                                           before.a0_coef);
      ChannelLoad load[NCHANNEL];
      tangential_load(c, (1.0 / dist) * d12, dist, atom->radius[p], atom->radius[q], S.R,
                      tangential_constants(before, S), load);
      for (int ch = 0; ch < NCHANNEL; ch++)
        if (off[ch]) C.ledger[i][CHANNEL_LEDGER[ch]] += 0.5 * load[ch].U;
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
