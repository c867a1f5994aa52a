// SPDX-License-Identifier: MIT
// Cross-check of lidet_ground_fit_plane (float centroid + 3x3 covariance + cyclic Jacobi) against
// Eigen's SelfAdjointEigenSolver in double precision: 500 random point sets shaped like ground
// patches (tens of metres long, centimetres of noise, tilted up to 20 deg, offset up to 60 m from
// the origin) plus near-isotropic blobs. The normals must agree within 1e-3 rad, the plane offsets
// within 1 cm, the eigenvalues within 1e-3 relative to the largest.
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "lidet/lidet.h"

int main()
{
    std::mt19937 gen(20261123u);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    std::normal_distribution<double> N(0.0, 1.0);
    int failures = 0;
    double worst_angle = 0.0, worst_d = 0.0, worst_eig = 0.0;
    for (int trial = 0; trial < 500; ++trial)
    {
        const bool blob = trial % 10 == 9;
        const int n = 20 + (int)(gen() % 2000u);
        // a random plane: normal within 20 deg of +z, passing 1-2 m below the origin
        const double tilt = 0.35 * std::fabs(U(gen)), dir = 3.14159265 * U(gen);
        Eigen::Vector3d nrm(std::sin(tilt) * std::cos(dir), std::sin(tilt) * std::sin(dir), std::cos(tilt));
        Eigen::Vector3d e1 = nrm.unitOrthogonal(), e2 = nrm.cross(e1);
        const double d = 1.0 + std::fabs(U(gen));
        const Eigen::Vector3d centre = 60.0 * Eigen::Vector3d(U(gen), U(gen), 0.0);
        const double len = 5.0 + 30.0 * std::fabs(U(gen)), wid = 1.0 + 10.0 * std::fabs(U(gen));
        const double noise = blob ? 3.0 : 0.01 + 0.05 * std::fabs(U(gen));
        std::vector<float> x(n), y(n), z(n);
        Eigen::MatrixXd P(n, 3);
        for (int i = 0; i < n; ++i)
        {
            Eigen::Vector3d p = centre + len * U(gen) * e1 + wid * U(gen) * e2 + noise * N(gen) * nrm;
            p -= (nrm.dot(centre) + d) * nrm; // on the plane n.p + d = 0 (plus noise)
            x[i] = (float)p.x();
            y[i] = (float)p.y();
            z[i] = (float)p.z();
            P.row(i) = Eigen::Vector3d(x[i], y[i], z[i]).transpose(); // the float inputs, in double
        }
        // reference: double covariance of the same float inputs
        const Eigen::RowVector3d mean = P.colwise().mean();
        const Eigen::MatrixXd C0 = P.rowwise() - mean;
        const Eigen::Matrix3d cov = (C0.transpose() * C0) / (double)n;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
        Eigen::Vector3d ref_n = es.eigenvectors().col(0);
        if (ref_n.z() < 0.0)
            ref_n = -ref_n;
        const double ref_d = -ref_n.dot(mean.transpose());

        lidet_plane_t pl;
        float eig[3];
        if (lidet_ground_fit_plane(x.data(), y.data(), z.data(), (uint32_t)n, &pl, eig) != LIDET_OK)
        {
            std::printf("trial %d: fit failed\n", trial);
            ++failures;
            continue;
        }
        const Eigen::Vector3d got(pl.nx, pl.ny, pl.nz);
        const double angle = std::acos(std::min(1.0, std::fabs(got.dot(ref_n)) / got.norm()));
        const double dd = std::fabs(pl.d_m - ref_d);
        double de = 0.0;
        for (int k = 0; k < 3; ++k)
            de = std::max(de, std::fabs(eig[k] - es.eigenvalues()(k)) / es.eigenvalues()(2));
        // a blob has no well-defined smallest direction: only its eigenvalues are compared
        if (!blob)
        {
            worst_angle = std::max(worst_angle, angle);
            worst_d = std::max(worst_d, dd);
        }
        worst_eig = std::max(worst_eig, de);
        if ((!blob && (angle > 1e-3 || dd > 0.01)) || de > 1e-3 || !(pl.nz >= 0.0f) ||
            std::fabs(got.norm() - 1.0) > 1e-5)
        {
            std::printf("trial %d (n %d, blob %d): angle %.3g rad, d err %.3g m, eig err %.3g\n", trial, n, (int)blob,
                        angle, dd, de);
            ++failures;
        }
    }
    std::printf("lidet_ground_fit_plane vs Eigen: worst normal angle %.3g rad, worst d %.3g m, worst eigenvalue "
                "%.3g (relative), failures %d\n",
                worst_angle, worst_d, worst_eig, failures);
    return failures == 0 ? 0 : 1;
}
