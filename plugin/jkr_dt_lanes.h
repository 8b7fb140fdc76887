/* jkr/dt: the tangential step of a block of contacts, four at a time.

   Most steps of most contacts take the tangential step's common path: the
   pointers turn by less than 0.01 rad and no displacement reaches its
   limit (tangential_common_step in jkr_dt_contact.h). The pair loop puts
   such contacts of a block here (put), one component per array, and step()
   takes them four at a time, one contact per lane of four doubles: the
   same functions as the one-contact step, on vectors, so each contact gets
   the same bits. A contact that leaves the common path in the step (a
   clamp, a fast turn) is taken again by tangential_step() alone, from its
   stored state, which step() has not yet written.

   One set of constants for all lanes (a scene of one material and one
   radius, ConstantsBy BY_SCENE in the pair), and contacts that store their
   pointers. No LAMMPS types.                                             */

#ifndef JKR_DT_LANES_H
#define JKR_DT_LANES_H

#include "jkr_dt_contact.h"

#include <cstring>

namespace JKRDT {

template <int N> struct TangentialLanes {
  static constexpr int W = 4;    // contacts per lane vector (Lanes4)
  static constexpr int CAP = (N + W - 1) / W * W;
  // the lanes' inputs: one array per component, room for a last, padded, group
  alignas(32) double d12[3][CAP], v12[3][CAP], w1[3][CAP], w2[3][CAP], n1[3][CAP], n2[3][CAP],
      F1[3][CAP], rinv[CAP], phi[CAP];
  // where each lane's contact came from and where its result goes
  const ContactMotion *motion[CAP];
  double *state[CAP];
  ContactResult *out[CAP];

  // contact e of the block: its motion, stored state, and the result of its normal step
  // (out->F1 the normal force, no torques, no tangential potentials or losses yet)
  void put(int e, const ContactMotion &m, double *values, const StateLayout &L,
           ContactResult &o)
  {
    const double *pointers = values + L.pointers;
    const V3 *vin[] = {&m.d12, &m.v12, &m.w1, &m.w2, &o.F1};
    double(*vout[])[CAP] = {d12, v12, w1, w2, F1};
    for (int a = 0; a < 5; a++) {
      vout[a][0][e] = vin[a]->x;
      vout[a][1][e] = vin[a]->y;
      vout[a][2][e] = vin[a]->z;
    }
    for (int k = 0; k < 3; k++) {
      n1[k][e] = pointers[k];
      n2[k][e] = pointers[3 + k];
    }
    rinv[e] = m.rinv;
    phi[e] = L.phi >= 0 ? values[L.phi] : 0.0;
    motion[e] = &m;
    state[e] = values;
    out[e] = &o;
  }

  // the count contacts put, four at a time (the last group's empty lanes repeat its first)
  void step(int count, const ContactConstants &c, const StateLayout &L, double dt,
            bool energy)
  {
    for (int e = count; e < (count + W - 1) / W * W; e++) copy_lane(e - e % W, e);
    for (int g = 0; g < count; g += W) step_group(g, count, c, L, dt, energy);
  }

private:
  void copy_lane(int from, int to)
  {
    for (int k = 0; k < 3; k++) {
      d12[k][to] = d12[k][from];
      v12[k][to] = v12[k][from];
      w1[k][to] = w1[k][from];
      w2[k][to] = w2[k][from];
      n1[k][to] = n1[k][from];
      n2[k][to] = n2[k][from];
      F1[k][to] = F1[k][from];
    }
    rinv[to] = rinv[from];
    phi[to] = phi[from];
  }

  static Lanes4 load(const double *a)
  {
    Lanes4 x;
    std::memcpy(&x, a, sizeof x);
    return x;
  }
  static V3T<Lanes4> load(const double (*a)[CAP], int g)
  {
    return {load(a[0] + g), load(a[1] + g), load(a[2] + g)};
  }

  void step_group(int g, int count, const ContactConstants &c, const StateLayout &L, double dt,
                  bool energy)
  {
    using T = Lanes4;
    ContactStateT<T> s = {load(n1, g), load(n2, g), load(phi + g)};
    V3T<T> F = load(F1, g);
    V3T<T> M1 = {T{}, T{}, T{}}, M2 = M1;
    T U[NCHANNEL] = {T{}, T{}, T{}};
    const auto on = tangential_common_step(c, load(d12, g), load(v12, g), load(w1, g),
                                           load(w2, g), load(rinv + g), dt, energy, s, F, M1,
                                           M2, U);
    for (int l = 0; l < W && g + l < count; l++) {
      const int e = g + l;
      ContactResult &o = *out[e];
      if (!on[l]) {    // off the common path: the whole tangential step, this contact alone
        tangential_step(c, L, *motion[e], dt, false, false, false, energy, state[e], o);
        continue;
      }
      double *pointers = state[e] + L.pointers;
      store(V3{s.n1.x[l], s.n1.y[l], s.n1.z[l]}, pointers);
      store(V3{s.n2.x[l], s.n2.y[l], s.n2.z[l]}, pointers + 3);
      if (L.phi >= 0) state[e][L.phi] = s.phi[l];
      o.F1 = {F.x[l], F.y[l], F.z[l]};
      o.M1 = {M1.x[l], M1.y[l], M1.z[l]};
      o.M2 = {M2.x[l], M2.y[l], M2.z[l]};
      if (energy)
        for (int ch = 0; ch < NCHANNEL; ch++) o.U[ch] = U[ch][l];
    }
  }
};

}    // namespace JKRDT

#endif
