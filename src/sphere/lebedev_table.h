// The Lebedev–Laikov orbit table (lebedev_table.cpp) and its layout.
#pragma once

namespace skybake::sphere_detail {

// Octahedral orbits (Lebedev's a_1, a_2, a_3, b_k, c_k, d_k):
//   A1: (±1, 0, 0) and permutations,            6 points
//   A2: (0, ±1/√2, ±1/√2) and permutations,    12 points
//   A3: (±1/√3, ±1/√3, ±1/√3),                  8 points
//   B : (±a, ±a, ±b), b = √(1 − 2a²), perms,   24 points
//   C : (±a, ±b, 0),  b = √(1 − a²),  perms,   24 points
//   D : (±a, ±b, ±c), c = √(1 − a² − b²), perms, 48 points
enum class OrbitKind : int { A1, A2, A3, B, C, D };

struct LebedevOrbit {
    OrbitKind kind;
    double a, b; // free coordinates (unused ones are 0)
    double v;    // weight of each point of the orbit
};

struct LebedevRuleInfo {
    int precision;
    int points;
    int first_orbit; // index into kLebedevOrbits
    int orbit_count;
};

extern const LebedevOrbit kLebedevOrbits[];
extern const LebedevRuleInfo kLebedevRules[];
extern const int kLebedevRuleCount;

} // namespace skybake::sphere_detail
