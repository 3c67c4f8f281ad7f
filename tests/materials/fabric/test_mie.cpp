// Tests of the Mie solver against published tables. Sources:
// [W] Wiscombe, "Mie scattering calculations: advances in technique and fast, vector-speed
//     computer codes", NCAR/TN-140+STR (1979, rev. 1996): the answers its test driver checks
//     (MVTstNew.f, BLOCK DATA CHEKMI; "obtained on a Cray computer using 14-digit precision",
//     7 significant figures), test cases 5-19. Read as transcribed in usask-arg/sasktran2
//     lib/tests/mie/linearized_mie.cpp and scottprahl/miepython tests/test_nojit.py (the two
//     agree). MIEV0 writes m = n - ik; its S1, S2 are the complex conjugates of ours.
// [D] Du, "Mie-scattering calculation", Appl. Opt. 43, 1951 (2004), Table 1 (Q_ext, Q_sca to 7
//     figures; cases a-m), as transcribed in ovidiopr/scattnlay
//     tests/mpmath_special_functions_test_generator.py.
// [BH] Bohren & Huffman, Absorption and Scattering of Light by Small Particles (1983),
//     Appendix A, p. 482: BHMIE's sample output for m = 1.55, lambda = 0.6328 um, r = 0.525 um.
// [MP] Independent 40-digit evaluations with mpmath (Bessel functions of half-integer order
//     from mpmath.besselj/bessely, or for D_n at large n a 30-digit downward recurrence started
//     2000 orders above 1.5 |z|, checked against a 4000-order start); written for these tests:
//       import mpmath as mp; mp.mp.dps = 40
//       h = lambda n, z: mp.sqrt(mp.pi * z / 2)
//       psi = lambda n, z: h(n, z) * mp.besselj(n + 0.5, z)
//       xi = lambda n, z: h(n, z) * (mp.besselj(n + 0.5, z) + 1j * mp.bessely(n + 0.5, z))
//       d = lambda f, n, z: f(n - 1, z) - n * f(n, z) / z  # psi_n', xi_n'
//       a_n = (m psi_n(mx) psi_n'(x) - psi_n(x) psi_n'(mx))
//             / (m psi_n(mx) xi_n'(x) - xi_n(x) psi_n'(mx))
//       b_n = (psi_n(mx) psi_n'(x) - m psi_n(x) psi_n'(mx))
//             / (psi_n(mx) xi_n'(x) - m xi_n(x) psi_n'(mx))
//     summed over as many terms as mie_term_count(x) with the BH formulas for Q and g.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/materials/fabric/mie.h"

using namespace weft;
using cd = std::complex<double>;

namespace {

double rel(double a, double b) {
  return std::abs(a - b) / std::abs(b);
}

struct WiscombeCase {
  int id;
  double x;
  cd m;  // our convention, k >= 0
  double qext, qsca, gqsca;
  cd s1[7], s2[7];  // MIEV0 convention as printed, at 0, 30, ..., 180 deg
};

// [W] CHEKMI, cases 5-19.
const WiscombeCase kWiscombe[] = {
    {5,
     0.099,
     {0.75, 0},
     7.417859e-6,
     7.417859e-6,
     1.074279e-8,
     {{1.817558e-8, -1.654225e-4},
      {1.817558e-8, -1.653815e-4},
      {1.817558e-8, -1.652694e-4},
      {1.817558e-8, -1.651163e-4},
      {1.817558e-8, -1.649631e-4},
      {1.817558e-8, -1.648510e-4},
      {1.817558e-8, -1.648100e-4}},
     {{1.817558e-8, -1.654225e-4},
      {1.574051e-8, -1.432172e-4},
      {9.087788e-9, -8.261265e-5},
      {9.797186e-23, 2.938374e-8},
      {-9.087788e-9, 8.250360e-5},
      {-1.574051e-8, 1.427725e-4},
      {-1.817558e-8, 1.648100e-4}}},
    {6,
     0.101,
     {0.75, 0},
     8.033542e-6,
     8.033542e-6,
     1.211000e-8,
     {{2.048754e-8, -1.756419e-4},
      {2.048754e-8, -1.755965e-4},
      {2.048753e-8, -1.754726e-4},
      {2.048751e-8, -1.753033e-4},
      {2.048750e-8, -1.751341e-4},
      {2.048749e-8, -1.750103e-4},
      {2.048749e-8, -1.749650e-4}},
     {{2.048754e-8, -1.756419e-4},
      {1.774273e-8, -1.520629e-4},
      {1.024377e-8, -8.771198e-5},
      {1.845057e-15, 3.247270e-8},
      {-1.024375e-8, 8.759147e-5},
      {-1.774269e-8, 1.515715e-4},
      {-2.048749e-8, 1.749650e-4}}},
    {7,
     10,
     {0.75, 0},
     2.232265,
     2.232265,
     2.001164,
     {{5.580662e1, -9.758097},
      {-7.672879, 1.087317e1},
      {3.587894, -1.756177},
      {-1.785905, -5.232828e-2},
      {1.537971, -8.329374e-2},
      {-4.140427e-1, 1.876851e-1},
      {-1.078568, -3.608807e-2}},
     {{5.580662e1, -9.758097},
      {-1.092923e1, 9.629667},
      {3.427411, 8.082691e-2},
      {-5.148748e-1, -7.027288e-1},
      {-6.908338e-1, 2.152693e-1},
      {5.247557e-1, -1.923391e-1},
      {1.078568, 3.608807e-2}}},
    {8,
     1000,
     {0.75, 0},
     1.997908,
     1.997908,
     1.688121,
     {{4.994770e5, -1.336502e4},
      {-3.999296e2, -3.316361e2},
      {-5.209852e2, -5.776614e2},
      {-1.600887e2, 1.348013e2},
      {8.431720e1, -1.209493e2},
      {-7.556092e1, -8.134810e1},
      {1.705778e1, 4.842510e2}},
     {{4.994770e5, -1.336502e4},
      {-3.946018e2, -1.147791e2},
      {-1.970767e2, -6.937470e2},
      {-4.152365e1, 1.143000e2},
      {-4.261732e1, 5.535055e1},
      {4.218303e1, 9.100831e1},
      {-1.705778e1, -4.842510e2}}},
    {9,
     1,
     {1.33, 1e-5},
     9.395198e-2,
     9.392330e-2,
     1.733048e-2,
     {{2.348800e-2, 2.281705e-1},
      {2.341722e-2, 2.217102e-1},
      {2.322408e-2, 2.046815e-1},
      {2.296081e-2, 1.828349e-1},
      {2.269820e-2, 1.625401e-1},
      {2.250635e-2, 1.486170e-1},
      {2.243622e-2, 1.437106e-1}},
     {{2.348800e-2, 2.281705e-1},
      {2.034830e-2, 1.938171e-1},
      {1.181704e-2, 1.075976e-1},
      {2.729533e-4, 6.702879e-3},
      {-1.114466e-2, -7.646326e-2},
      {-1.942300e-2, -1.271557e-1},
      {-2.243622e-2, -1.437106e-1}}},
    {10,
     100,
     {1.33, 1e-5},
     2.101321,
     2.096594,
     1.821854,
     {{5.253302e3, -1.243188e2},
      {-5.534573e1, -2.971881e1},
      {1.710488e1, -1.520096e1},
      {-3.655758, 8.769860},
      {2.414318, 5.380874e-1},
      {-1.222996, 3.283917e1},
      {-5.659205e1, 4.650974e1}},
     {{5.253302e3, -1.243188e2},
      {-8.467204e1, -1.999470e1},
      {3.310764e1, -2.709787},
      {-6.550512, -4.675370},
      {6.039011, -1.169971e1},
      {-9.653812, 1.474455e1},
      {5.659205e1, -4.650974e1}}},
    {11,
     10000,
     {1.33, 1e-5},
     2.004089,
     1.723857,
     1.564987,
     {{5.010222e7, -1.535815e5},
      {3.786814e3, -7.654293e3},
      {-2.731172e3, 1.326633e3},
      {-1.061003e3, -1.930155e2},
      {-1.058140e3, 2.298414e1},
      {-2.748855e3, 2.298181e3},
      {-1.821193e2, -9.519122e2}},
     {{5.010222e7, -1.535815e5},
      {5.074755e3, -7.515986e3},
      {-3.076558e3, -1.775975e2},
      {2.430920e2, 8.409836e1},
      {5.906487e1, -5.370283e2},
      {-8.036201e1, -4.939186},
      {1.821194e2, 9.519123e2}}},
    {12,
     0.055,
     {1.5, 1},
     1.014910e-1,
     1.131687e-5,
     5.558541e-9,
     {{7.675259e-5, 8.343879e-5},
      {7.674331e-5, 8.343495e-5},
      {7.671794e-5, 8.342445e-5},
      {7.668328e-5, 8.341012e-5},
      {7.664863e-5, 8.339578e-5},
      {7.662326e-5, 8.338529e-5},
      {7.661398e-5, 8.338145e-5}},
     {{7.675259e-5, 8.343879e-5},
      {6.646948e-5, 7.225169e-5},
      {3.838246e-5, 4.169695e-5},
      {3.132066e-8, -2.037399e-8},
      {-3.830082e-5, -4.171317e-5},
      {-6.634986e-5, -7.221887e-5},
      {-7.661398e-5, -8.338145e-5}}},
    {13,
     0.056,
     {1.5, 1},
     1.033467e-1,
     1.216311e-5,
     6.193255e-9,
     {{8.102381e-5, 8.807251e-5},
      {8.101364e-5, 8.806830e-5},
      {8.098587e-5, 8.805682e-5},
      {8.094795e-5, 8.804113e-5},
      {8.091003e-5, 8.802545e-5},
      {8.088228e-5, 8.801396e-5},
      {8.087213e-5, 8.800976e-5}},
     {{8.102381e-5, 8.807251e-5},
      {7.016844e-5, 7.626381e-5},
      {4.051865e-5, 4.401169e-5},
      {3.427277e-8, -2.229631e-8},
      {-4.042932e-5, -4.402945e-5},
      {-7.003755e-5, -7.622790e-5},
      {-8.087213e-5, -8.800976e-5}}},
    {14,
     1,
     {1.5, 1},
     2.336321,
     6.634538e-1,
     1.274736e-1,
     {{5.840802e-1, 1.905153e-1},
      {5.657020e-1, 1.871997e-1},
      {5.175251e-1, 1.784426e-1},
      {4.563396e-1, 1.671665e-1},
      {4.002117e-1, 1.566427e-1},
      {3.621572e-1, 1.493910e-1},
      {3.488438e-1, 1.468286e-1}},
     {{5.840802e-1, 1.905153e-1},
      {5.001610e-1, 1.456112e-1},
      {2.879639e-1, 4.105398e-2},
      {3.622847e-2, -6.182646e-2},
      {-1.748750e-1, -1.229586e-1},
      {-3.056823e-1, -1.438460e-1},
      {-3.488438e-1, -1.468286e-1}}},
    {15,
     100,
     {1.5, 1},
     2.097502,
     1.283697,
     1.091466,
     {{5.243754e3, -2.934167e2},
      {4.049055e1, -1.898456e1},
      {-2.646835e1, -1.929564e1},
      {1.268890e1, 2.397474e1},
      {5.149886, 2.290736e1},
      {-1.605395e1, 1.418642e1},
      {-2.029360e1, 4.384435}},
     {{5.243754e3, -2.934167e2},
      {2.019198e1, 3.110731},
      {9.152743, -7.470202},
      {-1.232914e1, -7.823167},
      {-7.173357, -1.655464e1},
      {1.448052e1, -1.393594e1},
      {2.029360e1, -4.384435}}},
    {16,
     10000,
     {1.5, 1},
     2.004368,
     1.236574,
     1.046525,
     {{5.010919e7, -1.753404e5},
      {-3.690394e3, -1.573897e3},
      {2.391551e2, 3.247786e3},
      {-2.607463e3, 7.414859e2},
      {-6.183154e2, 2.264970e3},
      {-3.368019e2, 2.115750e3},
      {-2.184719e2, -2.064610e3}},
     {{5.010919e7, -1.753404e5},
      {-9.333175e2, -1.839736e3},
      {-1.202951e3, -1.899647e2},
      {1.013073e3, -1.064666e3},
      {1.334826e2, -1.800859e3},
      {2.293862e2, -1.996754e3},
      {2.184719e2, 2.064610e3}}},
    {17,
     1,
     {10, 10},
     2.532993,
     2.049405,
     -2.267961e-1,
     {{6.332483e-1, 4.179305e-1},
      {6.162264e-1, 4.597163e-1},
      {5.736317e-1, 5.602514e-1},
      {5.238628e-1, 6.675352e-1},
      {4.825816e-1, 7.434033e-1},
      {4.570214e-1, 7.809867e-1},
      {4.485464e-1, 7.912365e-1}},
     {{6.332483e-1, 4.179305e-1},
      {5.573186e-1, 2.954338e-1},
      {3.525107e-1, -5.921611e-3},
      {7.881172e-2, -3.435544e-1},
      {-1.881212e-1, -6.028739e-1},
      {-3.793898e-1, -7.473279e-1},
      {-4.485464e-1, -7.912365e-1}}},
    {18,
     100,
     {10, 10},
     2.071124,
     1.836785,
     1.021648,
     {{5.177811e3, -2.633811e1},
      {5.227436e1, -1.270012e1},
      {-2.705712e1, -3.951751e1},
      {1.008860, 4.663027e1},
      {-1.505640e1, 4.333057e1},
      {-4.510770e1, 5.199554},
      {-4.145383e1, -1.821808e1}},
     {{5.177811e3, -2.633811e1},
      {-2.380252e1, -3.872567e-1},
      {2.585821e1, 3.323624e1},
      {-3.479935, -4.364245e1},
      {1.360634e1, -4.238302e1},
      {4.474564e1, -5.452513},
      {4.145383e1, 1.821808e1}}},
    {19,
     10000,
     {10, 10},
     2.005914,
     1.795393,
     9.842238e-1,
     {{5.014786e7, -1.206004e5},
      {-4.080090e3, -2.664399e3},
      {-1.224040e3, 4.596569e3},
      {-4.579490e3, -8.590486e2},
      {-3.356286e3, 3.125121e3},
      {-3.149584e3, 3.270358e3},
      {2.252480e3, -3.924468e3}},
     {{5.014786e7, -1.206004e5},
      {3.351286e3, 7.291906e2},
      {4.497446e2, -4.072999e3},
      {4.313394e3, 4.969719e2},
      {3.171910e3, -3.129068e3},
      {3.105243e3, -3.269355e3},
      {-2.252480e3, 3.924468e3}}},
};

std::vector<double> wiscombe_mu() {
  std::vector<double> mu;
  for (int i = 0; i < 7; ++i) mu.push_back(std::cos(deg_to_rad(30.0 * i)));
  return mu;
}

}  // namespace

TEST(Mie, WiscombeEfficienciesAndAsymmetry) {
  // Q_ext, Q_sca and g Q_sca to 1e-6 relative (the tables carry 7 figures).
  for (const auto& c : kWiscombe) {
    const MieResult r = mie_sphere(c.m, c.x);
    double qext = c.qext, qsca = c.qsca;
    if (c.id == 6) {
      // CHEKMI's 8.033542e-6 disagrees in the 7th figure with Du's Table 1 (8.033538e-6) and with
      // a 40-digit evaluation of the same 2-term sum, 8.0335381486e-6 [MP]; we use [D].
      qext = qsca = 8.033538e-6;
    }
    EXPECT_LE(rel(r.qext, qext), 1e-6) << "case " << c.id << " qext " << r.qext;
    EXPECT_LE(rel(r.qsca, qsca), 1e-6) << "case " << c.id << " qsca " << r.qsca;
    if (c.id == 5) {
      // MIEV0 answered case 5 with its small-particle formulas (x max(1, |m|) <= 0.1), whose
      // g Q_sca is 1.7e-6 off the series: 1.07427721081e-8 for the same 2 terms [MP].
      EXPECT_LE(rel(r.g * r.qsca, 1.07427721081e-8), 1e-9);
      EXPECT_LE(rel(r.g * r.qsca, c.gqsca), 2e-6);
    } else {
      EXPECT_LE(rel(r.g * r.qsca, c.gqsca), 1e-6) << "case " << c.id << " gqsca " << r.g * r.qsca;
    }
  }
}

TEST(Mie, WiscombeAmplitudes) {
  // S1, S2 at 0, 30, ..., 180 deg to 1e-6 of |S| (7 figures per component). Ours are the
  // complex conjugates of MIEV0's. Exceptions, where MIEV0's stored answer itself is good to
  // fewer figures: cases 5 and 12 come from MIEV0's small-particle formulas (x max(1, |m|) <=
  // 0.1), whose S2(90 deg) is a remainder ~1e-4 of the forward amplitude (case 12: ours,
  // 3.13206383e-8 + 2.03740487e-8 i, is the 2-term series to 1e-9 [MP]); case 6's S2 at 60 and
  // 120 deg carry the same 7th-figure offset as its Q (see above). For these we allow 5e-6.
  const std::vector<double> mu = wiscombe_mu();
  for (const auto& c : kWiscombe) {
    const MieResult r = mie_sphere(c.m, c.x, mu);
    for (int i = 0; i < 7; ++i) {
      const bool limited =
          ((c.id == 5 || c.id == 12) && i == 3) || (c.id == 6 && (i == 2 || i == 4));
      const double tol = limited ? 5e-6 : 1e-6;
      const cd e1 = std::conj(c.s1[i]), e2 = std::conj(c.s2[i]);
      EXPECT_LE(std::abs(r.s1[i] - e1), tol * std::abs(e1))
          << "case " << c.id << " S1 at " << 30 * i << " deg: " << r.s1[i] << " vs " << e1;
      EXPECT_LE(std::abs(r.s2[i] - e2), tol * std::abs(e2))
          << "case " << c.id << " S2 at " << 30 * i << " deg: " << r.s2[i] << " vs " << e2;
    }
  }
}

TEST(Mie, DuTable1) {
  // [D] Table 1: x, m, Q_ext, Q_sca (cases a-m).
  struct Row {
    double x;
    cd m;
    double qext, qsca;
  };
  const Row rows[] = {
      {0.099, {0.75, 0}, 7.417859e-06, 7.417859e-06},
      {0.101, {0.75, 0}, 8.033538e-06, 8.033538e-06},
      {10, {0.75, 0}, 2.232265, 2.232265},
      {1000, {0.75, 0}, 1.997908, 1.997908},
      {100, {1.33, 1e-5}, 2.101321, 2.096594},
      {10000, {1.33, 1e-5}, 2.004089, 1.723857},
      {0.055, {1.5, 1}, 0.101491, 1.131687e-05},
      {0.056, {1.5, 1}, 0.1033467, 1.216311e-05},
      {100, {1.5, 1}, 2.097502, 1.283697},
      {10000, {1.5, 1}, 2.004368, 1.236574},
      {1, {10, 10}, 2.532993, 2.049405},
      {100, {10, 10}, 2.071124, 1.836785},
      {10000, {10, 10}, 2.005914, 1.795393},
  };
  for (const auto& row : rows) {
    const MieResult r = mie_sphere(row.m, row.x);
    // 0.101491 is printed with 6 figures: half a unit is 5e-6 relative.
    const double tol_ext = row.qext == 0.101491 ? 5e-6 : 1e-6;
    EXPECT_LE(rel(r.qext, row.qext), tol_ext) << "x " << row.x << " m " << row.m;
    EXPECT_LE(rel(r.qsca, row.qsca), 1e-6) << "x " << row.x << " m " << row.m;
  }
}

TEST(Mie, BohrenHuffmanAppendixA) {
  // [BH] m = 1.55 in air, lambda = 0.6328 um, r = 0.525 um: QSCA = QEXT = 3.10543,
  // QBACK = 2.92534 (printed to 6 figures; half a unit of the last is 5e-6).
  const MieResult r = mie_sphere_physical(1.55, 0.0, 1.0, 0.525, 632.8);
  EXPECT_NEAR(r.x, 2 * std::numbers::pi * 0.525 / 0.6328, 1e-12);
  EXPECT_NEAR(r.qext, 3.10543, 5e-6);
  EXPECT_NEAR(r.qsca, 3.10543, 5e-6);
  EXPECT_NEAR(r.qback, 2.92534, 5e-6);
  // Q_back is 4 |S1(180 deg)|^2 / x^2 (BH eq. 4.82 with S1 = -S2 at 180 deg).
  const double mu[] = {-1.0};
  const MieResult s = mie_sphere(r.m, r.x, mu);
  EXPECT_NEAR(4 * std::norm(s.s1[0]) / (r.x * r.x), r.qback, 1e-12 * r.qback);
}

TEST(Mie, PhysicalFormUsesHostWavelengthAndRelativeIndex) {
  // The same sphere in water (n = 1.333) with particle index 1.55 * 1.333 at the same
  // wavelength: m is unchanged and x grows by 1.333.
  const MieResult air = mie_sphere_physical(1.55, 0.0, 1.0, 0.525, 632.8);
  const MieResult water = mie_sphere_physical(1.55 * 1.333, 0.0, 1.333, 0.525 / 1.333, 632.8);
  EXPECT_NEAR(water.x, air.x, 1e-12 * air.x);
  EXPECT_NEAR(water.m.real(), 1.55, 1e-15);
  EXPECT_NEAR(water.qext, air.qext, 1e-12);
  EXPECT_NEAR(mie_size_parameter(1.557, 0.25, 550.0), 2 * std::numbers::pi * 1.557 * 0.25 / 0.55,
              1e-12);
}

TEST(Mie, IndexNearOne) {
  // m = 1.0001 [MP]: x = 10 (20 terms): Q_sca = 1.940224336812e-6, g = 0.9714670388411;
  // x = 100 (120 terms): Q_sca = 1.999098376542e-4, g = 0.9994929077904.
  const MieResult a = mie_sphere({1.0001, 0}, 10);
  EXPECT_LE(rel(a.qsca, 1.940224336812127e-6), 1e-9);
  EXPECT_LE(rel(a.qext, 1.940224336812127e-6), 1e-9);
  EXPECT_NEAR(a.g, 0.9714670388410664, 1e-9);
  const MieResult b = mie_sphere({1.0001, 0}, 100);
  EXPECT_LE(rel(b.qsca, 1.999098376542486e-4), 1e-9);
  EXPECT_NEAR(b.g, 0.9994929077903539, 1e-9);
  // Large soft spheres approach anomalous diffraction (van de Hulst 1957, sec. 11.22):
  // Q_ext = 2 - (4 / rho) sin rho + (4 / rho^2)(1 - cos rho), rho = 2 x (m - 1).
  for (double x : {1e4, 1e5}) {
    const double rho = 2 * x * 1e-4;
    const double adt = 2 - 4 / rho * std::sin(rho) + 4 / (rho * rho) * (1 - std::cos(rho));
    const MieResult r = mie_sphere({1.0001, 0}, x);
    EXPECT_LE(rel(r.qext, adt), 1e-2) << "x " << x;
  }
}

TEST(Mie, RayleighLimit) {
  // x = 1e-6: Q_sca = 8/3 x^4 |K|^2, Q_abs = 4 x Im K (BH eqs. 5.7-5.8); next-order terms are
  // x^2 = 1e-12 relative, so agreement must be near rounding.
  for (const cd m :
       {cd(1.5, 0), cd(1.5, 1), cd(0.75, 0), cd(1.0001, 0), cd(10, 10), cd(1.33, 1e-5)}) {
    const double x = 1e-6;
    const MieResult r = mie_sphere(m, x);
    const MieResult ray = rayleigh_limit(m, x);
    EXPECT_LE(rel(r.qsca, ray.qsca), 1e-9) << m;
    EXPECT_LE(rel(r.qback, ray.qback), 1e-9) << m;
    if (m.imag() > 0) {
      EXPECT_LE(rel(r.qabs, ray.qabs), 1e-9) << m;
    }
    EXPECT_LE(std::abs(r.g), 1e-10) << m;
    EXPECT_TRUE(std::isfinite(r.qext));
  }
}

TEST(Mie, SmallSpheresKeepEveryFigure) {
  // Below x = 0.01 the numerators of a_1, b_1, a_2 come from Taylor series; above, from the
  // direct formulas. Both against [MP] (2-term sums): m = 1.5, x = 1e-3: Q_sca =
  // 2.306805237804225e-13, Q_back = 3.460206222719589e-13, g = 1.983333175635093e-7;
  // m = 1.5 + i, x = 1e-4: Q_ext = 1.840255607652422e-4, Q_sca = 1.235356767485556e-16,
  // g = 1.624842763101169e-9; m = 0.75, x = 0.01: Q_sca = 7.772627665421393e-10,
  // g = 1.47540192749003e-5. g is the quantity the direct difference loses (as eps / x^2).
  const MieResult a = mie_sphere({1.5, 0}, 1e-3);
  EXPECT_LE(rel(a.qsca, 2.306805237804225e-13), 1e-13);
  EXPECT_LE(rel(a.qback, 3.460206222719589e-13), 1e-13);
  EXPECT_LE(rel(a.g, 1.983333175635093e-7), 1e-13);
  const MieResult b = mie_sphere({1.5, 1}, 1e-4);
  EXPECT_LE(rel(b.qext, 1.840255607652422e-4), 1e-13);
  EXPECT_LE(rel(b.qsca, 1.235356767485556e-16), 1e-13);
  EXPECT_LE(rel(b.g, 1.624842763101169e-9), 1e-13);
  const MieResult c = mie_sphere({0.75, 0}, 0.01);
  EXPECT_LE(rel(c.qsca, 7.772627665421393e-10), 1e-13);
  EXPECT_LE(rel(c.g, 1.47540192749003e-5), 1e-10);
  // m = 10 + 10i, x = 1e-3 [MP]: Q_ext = 6.002075807479446e-5, Q_sca = 2.666469885851701e-12,
  // g = 1.165406186206481e-7. m = 1.0001, x = 5e-3 [MP]: Q_sca = 7.407086411558031e-18 (the
  // double nearest 1.0001 moves it by 2e-13).
  const MieResult d = mie_sphere({10, 10}, 1e-3);
  EXPECT_LE(rel(d.qext, 6.002075807479446e-5), 1e-13);
  EXPECT_LE(rel(d.qsca, 2.666469885851701e-12), 1e-13);
  EXPECT_LE(rel(d.g, 1.165406186206481e-7), 1e-13);
  EXPECT_LE(rel(mie_sphere({1.0001, 0}, 5e-3).qsca, 7.407086411558031e-18), 1e-12);
  // Continuity where the series hands over to the direct formulas.
  for (const cd m : {cd(1.5, 0), cd(1.33, 1e-5), cd(1.9, 0.2), cd(1.0001, 0)}) {
    const MieResult below = mie_sphere(m, 0.999999e-2), above = mie_sphere(m, 1.000001e-2);
    const double scale4 = std::pow(1.000001 / 0.999999, 4);
    EXPECT_LE(rel(above.qsca, below.qsca * scale4), 1e-5) << m;
    EXPECT_LE(rel(above.g, below.g), 1e-5) << m;
  }
}

TEST(Mie, EnergyBalance) {
  // Non-absorbing spheres absorb nothing (to rounding); absorbing ones absorb a positive amount
  // that stays below extinction.
  for (double x : {1e-6, 1e-3, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5}) {
    for (double n : {0.75, 1.0001, 1.33, 1.5, 2.7}) {
      const MieResult r = mie_sphere({n, 0}, x);
      EXPECT_LE(std::abs(r.qabs), 1e-11 * r.qext) << "x " << x << " n " << n;
      const MieResult a = mie_sphere({n, 1e-3}, x);
      EXPECT_GT(a.qabs, 0) << "x " << x << " n " << n;
      EXPECT_GT(a.qsca, 0) << "x " << x << " n " << n;
      EXPECT_LE(a.qabs, a.qext) << "x " << x << " n " << n;
    }
  }
}

TEST(Mie, PhaseFunctionIsNormalizedAndItsMeanCosineIsG) {
  // Integrate p over mu with composite Gauss-Legendre on a grid fine enough for the forward
  // peak: 2 pi int p dmu = 1 and 2 pi int mu p dmu = g (from the series' own formula).
  for (const auto& [m, x] : std::vector<std::pair<cd, double>>{{{1.5, 0}, 0.5},
                                                               {{1.55, 0}, 5.213},
                                                               {{1.33, 1e-5}, 50},
                                                               {{0.642, 0}, 20},
                                                               {{1.5, 1}, 30}}) {
    // Gauss-Legendre nodes on [-1, 1] by Newton, 16 per panel; panels in theta so the forward
    // peak (width ~1/x) is resolved.
    const int per = 16, panels = 400;
    std::vector<double> gx(per), gw(per);
    for (int i = 0; i < per; ++i) {
      double z = std::cos(std::numbers::pi * (i + 0.75) / (per + 0.5)), dp = 1;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = z;
        for (int k = 2; k <= per; ++k) {
          const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = per * (z * p1 - p0) / (z * z - 1);
        z -= p1 / dp;
      }
      gx[i] = z;
      gw[i] = 2 / ((1 - z * z) * dp * dp);
    }
    std::vector<double> mu, w;
    for (int p = 0; p < panels; ++p) {
      const double t0 = std::numbers::pi * p / panels, t1 = std::numbers::pi * (p + 1) / panels;
      for (int i = 0; i < per; ++i) {
        const double t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * gx[i];
        mu.push_back(std::cos(t));
        w.push_back(0.5 * (t1 - t0) * gw[i] * std::sin(t));  // dmu = sin theta dtheta
      }
    }
    const MieResult r = mie_sphere(m, x, mu);
    const std::vector<double> p = mie_phase_function(r);
    double norm = 0, mean = 0;
    for (size_t i = 0; i < mu.size(); ++i) {
      norm += 2 * std::numbers::pi * w[i] * p[i];
      mean += 2 * std::numbers::pi * w[i] * p[i] * mu[i];
    }
    EXPECT_NEAR(norm, 1.0, 1e-9) << m << " x " << x;
    EXPECT_NEAR(mean, r.g, 1e-9) << m << " x " << x;
  }
}

TEST(Mie, LogarithmicDerivative) {
  // D_n(z) against [MP]: z = 80 (1.05 + i) (the test of Du 2004, sec. 4), z = 1e4 (1.33 + 1e-5 i)
  // and z = 1e5 (1.05 + 1e-8 i), a large weakly absorbing sphere where a start at |z| + 15
  // (BHMIE) loses digits.
  struct Ref {
    cd z;
    int n;
    cd d;
  };
  const Ref refs[] = {
      {80.0 * cd(1.05, 1), 1, {7.4646038278327467e-5, -0.99999588653158334}},
      {80.0 * cd(1.05, 1), 50, {0.095292131517960655, -0.99934765404303649}},
      {80.0 * cd(1.05, 1), 100, {0.36132549545800974, -1.0445005262751153}},
      {80.0 * cd(1.05, 1), 130, {0.56738278359251165, -1.121108944274722}},
      {1e4 * cd(1.33, 1e-5), 1, {4.6166510324036454, -6.8983874160528772}},
      {1e4 * cd(1.33, 1e-5), 5000, {0.20744662643898832, -0.089949151880808988}},
      {1e4 * cd(1.33, 1e-5), 10088, {-0.89277028868393146, -0.12298356113227654}},
      {1e5 * cd(1.05, 1e-8), 1, {8.3245848769189794, -0.070303562225650436}},
      {1e5 * cd(1.05, 1e-8), 50000, {4.4668941834413412, -0.020726789972122809}},
      {1e5 * cd(1.05, 1e-8), 100000, {0.069916818676704679, -9.7849810226470028e-5}},
  };
  for (const auto& ref : refs) {
    const auto d = mie_log_derivatives(ref.z, ref.n);
    EXPECT_LE(std::abs(d[ref.n] - ref.d), 1e-9 * std::abs(ref.d))
        << "z " << ref.z << " n " << ref.n << ": " << d[ref.n];
  }
}

TEST(Mie, ExtremesStayFiniteAndBounded) {
  const double mu[] = {1.0, 0.5, 0.0, -1.0};
  for (double x : {1e-12, 1e-6, 1e-3, 1.0, 1e3, 1e5, 1e6}) {
    for (const cd m :
         {cd(1.5, 0), cd(1.5, 10), cd(10, 10), cd(1.0001, 0), cd(0.75, 0), cd(1.33, 1e-8)}) {
      const MieResult r =
          mie_sphere(m, x, x <= 1e5 ? std::span<const double>(mu) : std::span<const double>());
      EXPECT_TRUE(std::isfinite(r.qext) && std::isfinite(r.qsca) && std::isfinite(r.qback) &&
                  std::isfinite(r.g))
          << "x " << x << " m " << m;
      EXPECT_LE(std::abs(r.g), 1.0) << "x " << x << " m " << m;
      EXPECT_GE(r.qsca, 0.0);
      EXPECT_GE(r.qext, r.qsca * (1 - 1e-12)) << "x " << x << " m " << m;
      // Extinction paradox: Q_ext -> 2 for large spheres.
      if (x >= 1e5 && m != cd(1.0001, 0)) {
        EXPECT_NEAR(r.qext, 2.0, 0.01) << "x " << x << " m " << m;
      }
      for (const auto& s : r.s1) EXPECT_TRUE(std::isfinite(s.real()) && std::isfinite(s.imag()));
    }
  }
}

TEST(Mie, TermCountFollowsWiscombe) {
  EXPECT_EQ(mie_term_count(1e-6), 2);
  EXPECT_EQ(mie_term_count(1.0), 6);      // 1 + 4 + 1
  EXPECT_EQ(mie_term_count(10.0), 20);    // 10 + 4.05 * 2.154 + 2 = 20.7
  EXPECT_EQ(mie_term_count(1e4), 10088);  // 1e4 + 4 * 21.54 + 2 = 10088.2 (MIEV0's count)
}

TEST(Mie, AngleGridResolvesForwardPeak) {
  for (double x : {1e-3, 1.0, 20.0, 1e3, 1e5}) {
    const auto t = mie_angle_grid_rad(x, 20000);
    ASSERT_GE(t.size(), 2u);
    EXPECT_EQ(t.front(), 0.0);
    EXPECT_EQ(t.back(), std::numbers::pi);
    EXPECT_LE(t.size(), 20000u);
    for (size_t i = 1; i < t.size(); ++i) ASSERT_GT(t[i], t[i - 1]);
    // At least 10 nodes inside the first diffraction lobe (first zero near 3.83 / x).
    if (x >= 20) {
      size_t inside = 0;
      for (double v : t) inside += v < 3.83 / x;
      EXPECT_GE(inside, 10u) << "x " << x;
    }
  }
}

TEST(Mie, LognormalQuadratureMoments) {
  // <r^k> of a lognormal is r_med^k exp(k^2 sigma^2 / 2).
  const SizeDistribution d = SizeDistribution::lognormal(0.3, 0.5);
  const SizeQuadrature q = size_quadrature(d, 96);
  for (int k = 0; k <= 3; ++k) {
    double s = 0;
    for (size_t i = 0; i < q.radius_um.size(); ++i) s += q.weight[i] * std::pow(q.radius_um[i], k);
    EXPECT_LE(rel(s, std::pow(0.3, k) * std::exp(k * k * 0.25 / 2)), 1e-6) << "k " << k;
  }
}

TEST(Mie, EnsembleMatchesBruteForceAndNarrowLimit) {
  // Lognormal r_med = 0.25 um, sigma = 0.4, air voids (n = 1) in cellulose (1.557) at 550 nm:
  // the quadrature average of C_sca and g against a brute-force midpoint rule on 20000 radii.
  const SizeDistribution d = SizeDistribution::lognormal(0.25, 0.4);
  const double mu[] = {1.0, 0.0, -1.0};
  const MieEnsemble e = mie_ensemble(1.0, 0.0, 1.557, d, 550.0, mu);
  const double lo = std::log(0.25) - 6 * 0.4, hi = std::log(0.25) + 3 * 0.16 + 6 * 0.4;
  const int n = 20000;
  double wsum = 0, csca = 0, gc = 0, vol = 0;
  for (int i = 0; i < n; ++i) {
    const double t = lo + (i + 0.5) * (hi - lo) / n;
    const double z = (t - std::log(0.25)) / 0.4;
    const double w = std::exp(-0.5 * z * z);
    const double r = std::exp(t);
    const MieResult m = mie_sphere_physical(1.0, 0.0, 1.557, r, 550.0);
    wsum += w;
    csca += w * std::numbers::pi * r * r * m.qsca;
    gc += w * std::numbers::pi * r * r * m.qsca * m.g;
    vol += w * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  }
  EXPECT_LE(rel(e.mean_csca_um2, csca / wsum), 1e-4);
  EXPECT_NEAR(e.g, gc / csca, 1e-4);
  EXPECT_LE(rel(e.mean_volume_um3, vol / wsum), 1e-6);
  EXPECT_EQ(e.mean_cabs_um2, 0.0);
  // A very narrow lognormal tends to the monodisperse sphere.
  const MieEnsemble narrow =
      mie_ensemble(1.0, 0.0, 1.557, SizeDistribution::lognormal(0.25, 0.002), 550.0, mu);
  const MieResult mono = mie_sphere_physical(1.0, 0.0, 1.557, 0.25, 550.0, mu);
  EXPECT_LE(rel(narrow.qsca, mono.qsca), 1e-3);
  EXPECT_NEAR(narrow.g, mono.g, 1e-3);
  const std::vector<double> pm = mie_phase_function(mono);
  for (int j = 0; j < 3; ++j) EXPECT_LE(rel(narrow.phase[j], pm[j]), 1e-2) << j;
}

TEST(Mie, RejectsBadInput) {
  const double nan = std::nan("");
  EXPECT_THROW(mie_sphere({nan, 0}, 1), Error);
  EXPECT_THROW(mie_sphere({1.5, nan}, 1), Error);
  EXPECT_THROW(mie_sphere({1.5, -0.1}, 1), Error);
  EXPECT_THROW(mie_sphere({-1.5, 0}, 1), Error);
  EXPECT_THROW(mie_sphere({1.5, 0}, 0), Error);
  EXPECT_THROW(mie_sphere({1.5, 0}, -1), Error);
  EXPECT_THROW(mie_sphere({1.5, 0}, nan), Error);
  EXPECT_THROW(mie_sphere({1.5, 0}, INFINITY), Error);
  EXPECT_THROW(mie_sphere({1.5, 0}, 2e7), Error);
  EXPECT_THROW(mie_sphere({1.5, 0}, 1e-13), Error);
  EXPECT_NO_THROW(mie_sphere({10, 10}, 1e-12));
  const double bad_mu[] = {1.5};
  EXPECT_THROW(mie_sphere({1.5, 0}, 1, bad_mu), Error);
  EXPECT_THROW(mie_sphere_physical(1.5, 0, 1.557, -0.1, 550), Error);
  EXPECT_THROW(mie_sphere_physical(1.5, 0, 1.557, 0.1, 0), Error);
  EXPECT_THROW(mie_sphere_physical(1.5, 0, 0, 0.1, 550), Error);
  EXPECT_THROW(size_quadrature(SizeDistribution::lognormal(0.1, 0)), Error);
  EXPECT_THROW(size_quadrature(SizeDistribution::lognormal(0.1, 1.5)), Error);
  EXPECT_THROW(size_quadrature(SizeDistribution::monodisperse(nan)), Error);
  try {
    mie_sphere({1.5, 0}, -1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'x'"), std::string::npos) << e.what();
  }
}
