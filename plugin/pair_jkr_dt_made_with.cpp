/* jkr/dt: made_with, the constants every type pair's contacts were made with, as the
   contact fix keeps them and restart files carry them (to book the energy of a channel
   switched off after a read_restart, pair_jkr_dt_tangential.cpp).

   The record names each field: NAMED, the number of fields, each field's name (its
   length, then one character per value), then every type pair's values in that order.
   Read back by name, so that a reordered or added field cannot come back as another;
   a record that lacks a field this build needs reads back empty (nothing is booked),
   as does a record of another kind. Records written before the names (each Param's
   bytes behind sizeof(Param)) still read where the size matches.                     */

#include "pair_jkr_dt.h"

#include <cstring>
#include <string>

using namespace LAMMPS_NS;
using Param = PairJKRDT::Param;

namespace {

// the fields of Param, by name: a double or an int member
struct Field {
  const char *name;
  double Param::*real;
  int Param::*whole;
};

const Field FIELDS[] = {
    {"gamma", &Param::gamma, nullptr},         {"a0_coef", &Param::a0_coef, nullptr},
    {"damp_coef", &Param::damp_coef, nullptr}, {"xi_crit", &Param::xi_crit, nullptr},
    {"ks_coef", &Param::ks_coef, nullptr},     {"zeta_coef", &Param::zeta_coef, nullptr},
    {"k_r", &Param::k_r, nullptr},             {"kt_coef", &Param::kt_coef, nullptr},
    {"sliding", nullptr, &Param::sliding},     {"rolling", nullptr, &Param::rolling},
    {"twisting", nullptr, &Param::twisting},   {"damp_tension", nullptr, &Param::damp_tension},
    {"Estar", &Param::Estar, nullptr},         {"Gstar", &Param::Gstar, nullptr},
    {"Gred", &Param::Gred, nullptr},           {"nu", &Param::nu, nullptr},
    {"tvis", &Param::tvis, nullptr},           {"cut", &Param::cut, nullptr},
};
constexpr int NFIELD = sizeof(FIELDS) / sizeof(FIELDS[0]);
// 14 doubles and 4 ints: a field added to Param (or to JKRDT::Coefficients) goes in FIELDS
static_assert(sizeof(Param) == 14 * sizeof(double) + 4 * sizeof(int) && NFIELD == 18,
              "made_with names every field of PairJKRDT::Param: add the new one to FIELDS");
// the first value of a named record; a record of bytes starts with sizeof(Param) > 0
constexpr double NAMED = -1.0;

std::vector<Param> from_bytes(const std::vector<double> &record)
{
  constexpr size_t per = (sizeof(Param) + sizeof(double) - 1) / sizeof(double);
  if (record[0] != sizeof(Param) || (record.size() - 1) % per) return {};
  std::vector<Param> param((record.size() - 1) / per);
  for (size_t k = 0; k < param.size(); k++)
    std::memcpy(&param[k], &record[1 + k * per], sizeof(Param));
  return param;
}

}    // namespace

std::vector<double> PairJKRDT::made_with_record(const std::vector<Param> &param)
{
  std::vector<double> record = {NAMED, static_cast<double>(NFIELD)};
  for (const Field &f : FIELDS) {
    const std::string name = f.name;
    record.push_back(static_cast<double>(name.size()));
    for (const char c : name) record.push_back(static_cast<double>(c));
  }
  for (const Param &p : param)
    for (const Field &f : FIELDS)
      record.push_back(f.real ? p.*(f.real) : static_cast<double>(p.*(f.whole)));
  return record;
}

std::vector<Param> PairJKRDT::made_with_params(const std::vector<double> &record)
{
  if (record.empty()) return {};
  if (record[0] != NAMED) return from_bytes(record);
  // the record's field names, in its order
  size_t at = 2;
  const auto nfield = static_cast<size_t>(record.size() > 1 ? record[1] : 0);
  std::vector<std::string> names;
  for (size_t k = 0; k < nfield && at < record.size(); k++) {
    const auto length = static_cast<size_t>(record[at++]);
    if (at + length > record.size()) return {};
    std::string name;
    for (size_t c = 0; c < length; c++) name += static_cast<char>(record[at + c]);
    names.push_back(name);
    at += length;
  }
  if (names.size() != nfield || nfield == 0 || (record.size() - at) % nfield) return {};
  // where each field of this build sits among them
  int column[NFIELD];
  for (int f = 0; f < NFIELD; f++) {
    column[f] = -1;
    for (size_t k = 0; k < nfield; k++)
      if (names[k] == FIELDS[f].name) column[f] = static_cast<int>(k);
    if (column[f] < 0) return {};    // a field this build needs is not in the record
  }
  std::vector<Param> param((record.size() - at) / nfield);
  for (size_t k = 0; k < param.size(); k++) {
    const double *row = &record[at + k * nfield];
    for (int f = 0; f < NFIELD; f++) {
      if (FIELDS[f].real)
        param[k].*(FIELDS[f].real) = row[column[f]];
      else
        param[k].*(FIELDS[f].whole) = static_cast<int>(row[column[f]]);
    }
  }
  return param;
}
