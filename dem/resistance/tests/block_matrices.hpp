// The resistance blocks as Eigen matrices, for the tests' eigenvalue and projection checks.
#ifndef FDM_RESISTANCE_TESTS_BLOCK_MATRICES_HPP
#define FDM_RESISTANCE_TESTS_BLOCK_MATRICES_HPP

#include "fdm/resistance/blocks.hpp"

#include <Eigen/Dense>

typedef Eigen::Matrix<double, 12, 12> Matrix12;
typedef Eigen::Matrix<double, 12, 1> Vector12;

// the 12x12 force/torque block of a pair (U1 W1 U2 W2)
inline Matrix12 pairMatrix(const fdm::resistance::PairBlock& block)
{
    Matrix12 R;
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) R(i, j) = block.R[i][j];
    return R;
}

// the 6x6 force/torque block of a sphere and a wall (U W)
inline Eigen::Matrix<double, 6, 6> wallMatrix(const fdm::resistance::WallBlock& block)
{
    Eigen::Matrix<double, 6, 6> R;
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) R(i, j) = block.R[i][j];
    return R;
}

#endif
