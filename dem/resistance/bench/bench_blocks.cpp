// Cost of building the sub-grid blocks for 1000 particles with 6 close neighbours each (3000 pairs),
// median over repeats.  Usage: fdmResistanceBench [repeats=50] [calibrated]
// (calibrated: the squeeze calibration's model, CalibratedSubgridModel, with the shipped table)
#include "fdm/resistance/resistance.hpp"
#include "fdm/resistance/subgrid_calibration.hpp"

#include <memory>
#include <string>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

using namespace fdm::resistance;

namespace {

struct Pair {
    int i, j;
};

struct Triplet {
    int row, col;
    double value;
};

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

double secondsSince(const std::chrono::steady_clock::time_point& t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv)
{
    const int repeats = argc > 1 ? std::atoi(argv[1]) : 50;
    const bool calibrated = argc > 2 && std::string(argv[2]) == "calibrated";
    const int particles = 1000, neighbours = 6, pairs = particles * neighbours / 2;
    const double delta = 0.2;  // a/Delta = 5 (paper's resolution) for a = 1
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> unit(-1, 1);

    // Bidisperse radii 1 and 1.4 (the paper's pair); each pair placed at a gap inside the correction range.
    std::vector<double> radius(particles);
    for (int p = 0; p < particles; ++p) radius[p] = (p % 2) ? 1.4 : 1.0;
    std::vector<Pair> list(pairs);
    std::vector<double> x(3 * particles), x2(3 * pairs);
    for (int p = 0; p < particles; ++p)
        for (int k = 0; k < 3; ++k) x[3 * p + k] = 20 * unit(rng);
    for (int n = 0; n < pairs; ++n) {
        list[n].i = (n * 2) % particles;
        list[n].j = (n * 2 + 1 + 2 * (n / particles)) % particles;
        const double aMean = 0.5 * (radius[list[n].i] + radius[list[n].j]);
        const double xi = std::exp(std::log(1e-4) + (std::log(0.9 * delta / aMean) - std::log(1e-4)) * (0.5 + 0.5 * unit(rng)));
        double d[3] = {unit(rng), unit(rng), unit(rng)};
        const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; ++k) x2[3 * n + k] = x[3 * list[n].i + k] + aMean * (2 + xi) * d[k] / norm;
    }

    std::unique_ptr<SubgridModel> owned;
    if (calibrated)
        owned.reset(new CalibratedSubgridModel(SubgridCalibration::read(SubgridCalibration::defaultPath()), delta, 1.0, 1.0));
    else
        owned.reset(new CutoffSubgridModel(delta, 1.0));
    const SubgridModel& model = *owned;
    const std::chrono::steady_clock::time_point tFirst = std::chrono::steady_clock::now();
    PairBlock block;
    for (int n = 0; n < pairs; ++n) subgridPairBlock(model, &x[3 * list[n].i], &x2[3 * n], radius[list[n].i], radius[list[n].j], 1.0, block);
    const double firstCall = secondsSince(tFirst);

    std::vector<Triplet> triplets;
    triplets.reserve(144 * pairs);
    std::vector<double> blocksOnly, withScatter;
    double checksum = 0;
    for (int r = 0; r < repeats; ++r) {
        std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
        for (int n = 0; n < pairs; ++n) {
            if (subgridPairBlock(model, &x[3 * list[n].i], &x2[3 * n], radius[list[n].i], radius[list[n].j], 1.0, block))
                checksum += block.R[0][0];
        }
        blocksOnly.push_back(secondsSince(t0));

        t0 = std::chrono::steady_clock::now();
        triplets.clear();
        for (int n = 0; n < pairs; ++n) {
            if (!subgridPairBlock(model, &x[3 * list[n].i], &x2[3 * n], radius[list[n].i], radius[list[n].j], 1.0, block)) continue;
            const int base[2] = {6 * list[n].i, 6 * list[n].j};
            for (int i = 0; i < 12; ++i)
                for (int j = 0; j < 12; ++j) {
                    const Triplet t = {base[i / 6] + i % 6, base[j / 6] + j % 6, block.R[i][j]};
                    triplets.push_back(t);
                }
        }
        withScatter.push_back(secondsSince(t0));
    }

    // Wall blocks: one per particle, radius 1 (a/Delta 5: the calibration's largest), gaps eps = 1e-4 ... 0.9
    std::vector<double> wallEps(particles);
    for (int p = 0; p < particles; ++p) wallEps[p] = std::exp(std::log(1e-4) + (std::log(0.9) - std::log(1e-4)) * (0.5 + 0.5 * unit(rng)));
    const double wallPoint[3] = {0, 0, 0}, wallNormal[3] = {0, -1, 0};
    std::vector<double> wallBlocks;
    WallBlock wallBlock;
    for (int r = 0; r < repeats; ++r) {
        const std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
        for (int p = 0; p < particles; ++p) {
            const double centre[3] = {x[3 * p], 1 + wallEps[p], x[3 * p + 2]};
            if (subgridWallBlock(model, centre, 1.0, wallPoint, wallNormal, 1.0, wallBlock))
                checksum += wallBlock.R[0][0];
        }
        wallBlocks.push_back(secondsSince(t0));
    }

    // Per-new-lambda cost (cache miss): constants for a radius pair never seen before.
    std::vector<double> miss;
    for (int r = 0; r < 20; ++r) {
        const std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
        const PairForms forms = makePairForms(1.0, 1.0 + 0.01 * (r + 1));
        checksum += forms.f[XA][0][0].c0;
        miss.push_back(secondsSince(t0));
    }

    std::printf("fdmResistanceBench: %d particles x %d neighbours = %d pairs (radii 1 and 1.4, a/Delta = 5), %d repeats, %s\n",
                particles, neighbours, pairs, repeats, model.describe());
    std::printf("| what | median |\n|---|---|\n");
    std::printf("| %d sub-grid pair blocks (12x12 + stress rows), cached constants | %.3f ms |\n", pairs, 1e3 * median(blocksOnly));
    std::printf("| same + scatter into 6N triplets (%d entries) | %.3f ms |\n", 144 * pairs, 1e3 * median(withScatter));
    std::printf("| per pair | %.0f ns |\n", 1e9 * median(blocksOnly) / pairs);
    std::printf("| per wall block (radius 1, eps 1e-4 ... 0.9) | %.0f ns |\n", 1e9 * median(wallBlocks) / particles);
    std::printf("| first pass (series recurrences + constants for 2 radius pairs) | %.1f ms |\n", 1e3 * firstCall);
    std::printf("| constants for one new radius pair (lambda and 1/lambda sums) | %.3f ms |\n", 1e3 * median(miss));
    std::printf("(checksum %g)\n", checksum);
    return 0;
}
