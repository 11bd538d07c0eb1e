#include "fdm/resistance/sphere_wall.hpp"
#include "fdm/resistance/two_sphere.hpp"

#include <algorithm>
#include <cmath>

namespace fdm {
namespace resistance {

namespace {
// Chaoui & Feuillebois, Q. J. Mech. Appl. Math. 56 (2003) 381: Pade coefficients of Tables 9 (f_xx^t),
// 10 (c_yx^t) and 12 (c_yy^r) in x = a/h, and small-gap coefficients of Tables 11 and 13,
// X = sum_j (A_j ln eps + B_j) eps^j; as transcribed in ilent2/ott (+ott/+drag/ChaouiSphere.m,
// PadeSphere.m); test SphereWall.MatchesChaouiFeuillebois compares with their evaluation (tests/data).
const double padeParallelTranslationForceNumerator[39] = {1.0000000000000000, 0.4908044826583015, -5.9089832134410898, -3.5131616290239789, 15.8084387577986870, 11.3026454259591860, -25.4204600037753040, -22.1471886954821320, 27.7560683302883220, 29.9526704556636040, -22.5314407803093640, -29.8531751466299120, 15.1220023457727230, 22.7366718877015930, -9.3218018365645854, -13.5313752142074220, 5.3051235132574242, 6.4704436057717105, -2.4665892743626681, -2.6437641575552702, 0.7771314187961326, 1.0105989058549130, -0.0982971888072048, -0.3696484621597229, -0.0388403557770505, 0.1178052153278498, 0.0239731345108428, -0.0296092414452849, -0.0051932812835911, 0.0051959782885691, 0.0004467306955688, -0.0005090795488796, -0.0002283634635380, 0.0001112835192454, 0.0001947778117732, -0.0000777784823648, -0.0000608432770399, 0.0000204062418828, 0.0000083269893273};
const double padeParallelTranslationForceDenominator[39] = {1.0000000000000000, -0.0716955173416986, -6.1850607349363846, -0.0643585714633657, 17.6701614844569620, 1.5230014975500095, -31.0142617248087940, -4.9543202018606971, 37.7762831912656620, 8.6523092950119675, -34.4875979228363790, -9.7299979046697445, 25.1038379563044960, 7.4296786502390768, -15.2740433268190130, -3.8514631848696728, 7.9065568461965441, 1.3310163345710742, -3.4254372671567435, -0.3653047198870711, 1.2135904493519249, 0.1773693978765500, -0.3562252726334449, -0.1215738645617847, 0.0924829508022898, 0.0570985338450345, -0.0223176692443156, -0.0163260360921365, 0.0049336345493305, 0.0024740275532692, -0.0007151856250505, -0.0001540322172991, -0.0000432110135947, 0.0001218740679878, 0.0000315676817145, -0.0000901590239588, 0.0000136958535388, 0.0000157506941068, -0.0000020983554747};
const double padeTranslationRotationCouplingNumerator[39] = {0.0000000000000000, 0.0000000000000000, 0.0000000000000000, 0.0000000000000000, 0.0937500000000000, 0.0354462028356808, -0.5794683008061320, -0.1591806968088001, 1.6842716605855981, 0.2590332240370517, -3.0399314551829391, -0.0645486159987336, 3.7757798299644287, -0.4424917088086144, -3.3696060827666314, 0.8677197790058497, 2.1860298844040456, -0.8761868169616034, -1.0192554133470433, 0.5698017880599795, 0.3294504504024299, -0.2542214172218537, -0.0689937284425019, 0.0806987107131334, 0.0097549766071051, -0.0201417209825254, -0.0030113344253303, 0.0057346579076300, 0.0016237250709576, -0.0024134043883321, -0.0002857520641057, 0.0009078237305454, -0.0001481233143099, -0.0002045995112581, 0.0001062038845836, 0.0000104657146092, -0.0000268057642468, 0.0000075227992668, -0.0000007108447371};
const double padeTranslationRotationCouplingDenominator[39] = {1.0000000000000000, 0.7530928302472617, -5.6876478972560180, -4.6001625314679311, 14.7688208805162220, 12.9110364270167750, -23.2985876342930280, -22.2529692918405930, 25.2949343649485390, 26.5642830424431010, -20.7275046216581170, -23.5088999441590650, 14.1983612865681630, 16.1120087317810350, -8.9979341047037718, -8.7887426960210036, 5.4292449518028008, 3.8751690379208039, -2.9222312270789970, -1.3986551339586100, 1.2921105899769376, 0.4215695555772232, -0.4481976016305430, -0.1083283065391708, 0.1241851919484450, 0.0237060050706818, -0.0323930735345231, -0.0041438522586214, 0.0102787025544772, 0.0000794121908992, -0.0034959095257686, 0.0004233705581285, 0.0009223046179774, -0.0002180191880766, -0.0001333546201417, 0.0000637844613933, -0.0000096296739955, -0.0000116959858281, -0.0000022007617119};
const double padeParallelRotationTorqueNumerator[38] = {1.0000000000000000, -7.5838964357215906, -4.5207915154522071, 67.1126014324299830, 36.4257465110401740, -227.5434101958574600, -148.8868387007147800, 425.6988546482454000, 322.9424771530482900, -511.7610421660615400, -433.3830394473827700, 435.5861115275547500, 393.9363791481090400, -289.7726603465931700, -257.2538676239515800, 169.8215795297231200, 127.1823575386862300, -94.8269310329440460, -50.9124722094202300, 48.3584924238158750, 18.1172702688163230, -20.2524941264342860, -6.1301321875823511, 6.4841086908589745, 1.8629524433630982, -1.6546410482740759, -0.4418054918716946, 0.4474639134552081, 0.0855305535945268, -0.1492902692086656, -0.0198209692030472, 0.0387758704005577, -0.0004298844398339, -0.0066929563118655, 0.0026047337056495, 0.0008666597716715, -0.0005406029268510, -0.0000112860358089};
const double padeParallelRotationTorqueDenominator[38] = {1.0000000000000000, -7.5838964357215906, -4.5207915154522071, 66.8001014324299830, 38.7957141472031710, -226.1306628472786400, -169.9181203983491500, 414.7601777953258900, 394.3029642171122800, -469.1169610571635100, -568.1911141292858900, 347.3528087832515900, 559.5050863555197800, -177.4883257131791400, -401.8573592578553100, 74.3740852975847130, 223.4938946349586800, -37.7348164935060740, -103.2373672310176600, 22.7665029241817970, 42.6727488787292800, -10.3674675169848310, -16.2280741114435580, 2.4385277545819979, 5.2925499604112982, 0.0727424296455357, -1.2955329800216224, -0.1458737659618503, 0.2286349421460986, -0.0234720672648906, -0.0497699599389199, 0.0277057758052075, 0.0127677985914393, -0.0062955861393704, -0.0007922566399001, 0.0007258586021021, 0.0000013255383408, 0.0000755918974562};
const double smallGapParallelTranslationForceLog[6] = {-0.533333333333333, -0.170666666666667, 0.011595712294862, -0.002559314461340, 0.002165777707452, 0.000351260314552};
const double smallGapParallelTranslationForceConst[6] = {0.954293724783876, 0.429450132564500, -0.001897844702304, 0.002058408405495, 0.000096108639584, -0.001248147281379};
const double smallGapTranslationRotationCouplingLog[6] = {-0.1, -0.172, -0.036913066460225, 0.001486892317125, 0.000012689734456, 0.000103798994187};
const double smallGapTranslationRotationCouplingConst[6] = {-0.192952745666190, 0.100579155700110, 0.094493729126963, 0.003821112414990, -0.000819028830091, -0.000097511506358};
const double smallGapParallelRotationTorqueLog[6] = {-0.4, -0.528001276176667, -0.212879560114862, -0.035965644690736, -0.006385459746252, 0.000167620439255};
const double smallGapParallelRotationTorqueConst[6] = {0.370892565890165, 0.340079923061464, 0.225531274283815, 0.097897336215370, 0.005878696055717, 0.001503759398496};

template <int N, int M>
double pade(const double (&numerator)[N], const double (&denominator)[M], double x)
{
    double p = 0, q = 0;
    for (int k = N - 1; k >= 0; --k) p = p * x + numerator[k];
    for (int k = M - 1; k >= 0; --k) q = q * x + denominator[k];
    return p / q;
}

double smallGap(const double (&logCoef)[6], const double (&constCoef)[6], double eps)
{
    const double logEps = std::log(eps);
    double sum = 0;
    for (int j = 5; j >= 0; --j) sum = sum * eps + (logCoef[j] * logEps + constCoef[j]);
    return sum;
}

const double smallGapLimit = 0.1;      // below: small-gap forms; above: Pade (CF 2003, section 6)
const double brennerLubricationLimit = 1e-3;
const double pi = 3.14159265358979323846;
}  // namespace

const char* wallFunctionName(WallFunction f)
{
    static const char* names[NumWallFunctions] = {"XA", "YA", "YB", "XC", "YC", "XG", "YG", "YH", "XP"};
    return names[f];
}

double brennerNormalTranslationSeries(double eps)
{
    // Brenner, Chem. Eng. Sci. 16 (1961) 242, Eq. (2.19); cosh(alpha) = h/a.
    const double alpha = std::acosh(1 + eps);
    const double sinhAlpha = std::sinh(alpha), sinh2Alpha = std::sinh(2 * alpha);
    double sum = 0;
    for (int n = 1;; ++n) {
        const double twoNPlus1 = 2 * n + 1;
        if (twoNPlus1 * alpha > 40) break;  // remaining terms < e^-40 relative
        const double sh = std::sinh((n + 0.5) * alpha);
        const double numerator = 2 * std::sinh(twoNPlus1 * alpha) + twoNPlus1 * sinh2Alpha;
        const double denominator = 4 * sh * sh - twoNPlus1 * twoNPlus1 * sinhAlpha * sinhAlpha;
        sum += n * (n + 1.0) / ((2 * n - 1.0) * (2 * n + 3.0)) * (numerator / denominator - 1);
    }
    return 4.0 / 3.0 * sinhAlpha * sum;
}

double wallNormalTranslation(double eps)
{
    eps = std::max(eps, minimumGap);
    if (eps >= brennerLubricationLimit) return brennerNormalTranslationSeries(eps);
    // Cox & Brenner, Chem. Eng. Sci. 22 (1967) 1753: matches the series to 1e-6 relative at 1e-3
    return 1 / eps + 0.2 * std::log(1 / eps) + 0.971264;
}

double wallParallelTranslation(double eps)
{
    eps = std::max(eps, minimumGap);
    if (eps < smallGapLimit) return smallGap(smallGapParallelTranslationForceLog, smallGapParallelTranslationForceConst, eps);
    return pade(padeParallelTranslationForceNumerator, padeParallelTranslationForceDenominator, 1 / (1 + eps));
}

double wallCouplingMagnitude(double eps)
{
    eps = std::max(eps, minimumGap);
    if (eps < smallGapLimit) return smallGap(smallGapTranslationRotationCouplingLog, smallGapTranslationRotationCouplingConst, eps);
    return pade(padeTranslationRotationCouplingNumerator, padeTranslationRotationCouplingDenominator, 1 / (1 + eps));
}

double wallParallelRotation(double eps)
{
    eps = std::max(eps, minimumGap);
    if (eps < smallGapLimit) return smallGap(smallGapParallelRotationTorqueLog, smallGapParallelRotationTorqueConst, eps);
    return pade(padeParallelRotationTorqueNumerator, padeParallelRotationTorqueDenominator, 1 / (1 + eps));
}

double wallNormalRotation(double eps)
{
    // Jeffery, Proc. London Math. Soc. 14 (1915) 327: T = 8 pi mu a^3 Omega sinh^3(alpha) sum_n csch^3(n alpha).
    // First K terms directly, the rest by Euler-Maclaurin with the closed-form integral of csch^3.
    eps = std::max(eps, minimumGap);
    const double alpha = std::acosh(1 + eps);
    const int K = 40;
    double sum = 0;
    for (int n = 1; n < K; ++n) {
        const double c = 1 / std::sinh(n * alpha);
        sum += c * c * c;
    }
    const double U = K * alpha;
    const double cschU = 1 / std::sinh(U), cothU = 1 / std::tanh(U);
    const double integral = (0.5 * cschU * cothU - 0.5 * std::log(1 / std::tanh(U / 2))) / alpha;  // int_K^inf
    const double fK = cschU * cschU * cschU;
    const double dfK = -3 * alpha * fK * cothU;  // d/dn csch^3(n alpha) at n = K
    sum += integral + 0.5 * fK - dfK / 12;
    const double s = std::sinh(alpha);
    return s * s * s * sum;
}

WallScalars wallTheory(double eps)
{
    eps = std::max(eps, minimumGap);
    WallScalars w;
    w.f[WallXA] = wallNormalTranslation(eps);
    w.f[WallYA] = wallParallelTranslation(eps);
    w.f[WallYB] = -2 * wallCouplingMagnitude(eps);  // T = 8 pi a^2 c_yx U = 4 pi a^2 |Y^B| U
    w.f[WallXC] = wallNormalRotation(eps);
    w.f[WallYC] = wallParallelRotation(eps);
    w.f[WallXG] = 1.5 / eps - 1.2 * std::log(1 / eps);
    // pressure moment: lambda -> inf limit of the two-sphere X^P (docs/resistance.md): 1/eps plus
    // (g2 + 1 - 2) ln(1/eps) with Cox & Brenner's g2 = 1/5; O(1) constant not known
    w.f[WallXP] = 1 / eps - 0.8 * std::log(1 / eps);
    // D.4 in Kim-Karrila units (a = 1): Y^G = [(1+eps) 6 pi Y^A + 1/2 4 pi Y^B] / (4 pi), etc.
    w.f[WallYG] = (1 + eps) * 1.5 * w.f[WallYA] + 0.5 * w.f[WallYB];
    w.f[WallYH] = -(1 + eps) * 0.5 * w.f[WallYB] - 0.5 * w.f[WallYC];
    return w;
}

double wallKimKarrilaFactor(WallFunction f, double a)
{
    switch (f) {
    case WallXA: case WallYA: return 6 * pi * a;
    case WallYB: case WallXG: case WallYG: return 4 * pi * a * a;
    case WallXC: case WallYC: case WallYH: return 8 * pi * a * a * a;
    case WallXP: return 6 * pi * a * a;
    default: return 0;
    }
}

WallScalars wallTheoryDimensional(double a, double eps)
{
    WallScalars w = wallTheory(eps);
    for (int i = 0; i < NumWallFunctions; ++i) w.f[i] *= wallKimKarrilaFactor(WallFunction(i), a);
    return w;
}

void applyWallClosureD4(WallScalars& w, double a, double eps)
{
    w.f[WallYG] = (1 + eps) * a * w.f[WallYA] + 0.5 * w.f[WallYB];
    w.f[WallYH] = -(1 + eps) * a * w.f[WallYB] - 0.5 * w.f[WallYC];
}

}  // namespace resistance
}  // namespace fdm
