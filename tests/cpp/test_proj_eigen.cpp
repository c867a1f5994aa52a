// SPDX-License-Identifier: MIT
// Cross-check of lidet_proj against a double-precision Eigen reference, for every sensor preset:
// thousands of random points per profile, row/column agreement >= 99.9%, and every disagreement
// must lie within 1e-5 rad of the bin boundary it straddles (float rounding, not a logic error).
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "lidet/lidet.h"

namespace
{
lidet_proj_t g_proj;

struct Result
{
    int checked = 0;
    int row_disagree = 0;
    int col_disagree = 0;
    int bad = 0; // disagreements away from a boundary
};

Result check_profile(const char *name, std::mt19937 &gen)
{
    Result res;
    const lidet_sensor_t *s = lidet_sensor_find(name);
    lidet_proj_cfg_t cfg;
    lidet_proj_cfg_default(&cfg, s);
    if (lidet_proj_init(&g_proj, &cfg) != LIDET_OK)
    {
        res.bad = 1;
        return res;
    }
    lidet_range_image_t img;
    lidet_proj_image(&g_proj, &img);
    const int rows = img.n_rows, cols = img.n_cols;
    // beam elevations (row order) and mid-angles in double
    Eigen::VectorXd elev(rows);
    for (int r = 0; r < rows; ++r)
        elev[r] = img.row_elev_rad[r];
    Eigen::VectorXd mids = 0.5 * (elev.head(rows - 1) + elev.tail(rows - 1));

    const int n = 20000;
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::vector<float> pts(4 * n);
    Eigen::Matrix<double, Eigen::Dynamic, 3> P(n, 3);
    for (int i = 0; i < n; ++i)
    {
        const double el = elev[rows - 1] + (elev[0] - elev[rows - 1]) * U(gen);
        const double az = -M_PI + 2.0 * M_PI * U(gen);
        const double r = 1.0 + 79.0 * U(gen);
        Eigen::Vector3d p(r * std::cos(el) * std::cos(az), r * std::cos(el) * std::sin(az), r * std::sin(el));
        for (int k = 0; k < 3; ++k)
            pts[4 * i + k] = static_cast<float>(p[k]);
        pts[4 * i + 3] = 0.0f;
        // the reference sees exactly the float inputs lidet sees
        P.row(i) = Eigen::Vector3d(pts[4 * i], pts[4 * i + 1], pts[4 * i + 2]).transpose();
    }
    if (lidet_proj_run(&g_proj, pts.data(), n, 4, nullptr) != LIDET_OK)
    {
        res.bad = 1;
        return res;
    }
    uint32_t np = 0;
    const int32_t *pp = lidet_proj_point_pixels(&g_proj, &np);
    const double tol = 1e-5;
    for (int i = 0; i < n; ++i)
    {
        const Eigen::Vector3d p = P.row(i).transpose();
        const double rxy = p.head<2>().norm();
        const double el = std::atan2(p.z(), rxy);
        const double az = std::atan2(p.y(), p.x());
        // reference row: number of mid-angles strictly above el; column: floor formula
        int row = 0;
        while (row < rows - 1 && mids[row] > el)
            ++row;
        double u = 0.5 * (1.0 - az / M_PI) * cols;
        int col = static_cast<int>(std::floor(u));
        col = col >= cols ? col - cols : col;
        if (pp[i] < 0)
        {
            ++res.bad; // every point here is inside the field of view
            continue;
        }
        ++res.checked;
        const int lrow = pp[i] / cols, lcol = pp[i] % cols;
        if (lrow != row)
        {
            ++res.row_disagree;
            const double dist = (mids.array() - el).abs().minCoeff();
            res.bad += dist > tol;
        }
        if (lcol != col)
        {
            ++res.col_disagree;
            const double frac = u - std::floor(u + 0.5); // distance to the nearest column edge, in columns
            res.bad += std::fabs(frac) * (2.0 * M_PI / cols) > tol;
        }
    }
    return res;
}
} // namespace

int main()
{
    const char *names[] = {"hdl64", "vlp16", "vlp32c", "os1-64", "os1-128", "hdl32", "os0-32",
                           "os0-64", "os0-128", "os1-32", "os2-32", "os2-64", "os2-128", "pandar64"};
    std::mt19937 gen(12345);
    int failures = 0;
    for (const char *name : names)
    {
        const Result r = check_profile(name, gen);
        const double agree_row = r.checked ? 1.0 - double(r.row_disagree) / r.checked : 0.0;
        const double agree_col = r.checked ? 1.0 - double(r.col_disagree) / r.checked : 0.0;
        const bool ok = r.checked > 19000 && agree_row >= 0.999 && agree_col >= 0.999 && r.bad == 0;
        std::printf("%-8s checked %d  row agreement %.5f  col agreement %.5f  off-boundary disagreements %d  %s\n",
                    name, r.checked, agree_row, agree_col, r.bad, ok ? "OK" : "FAIL");
        failures += !ok;
    }
    std::printf("%d passed, %d failed\n", (int)(sizeof names / sizeof names[0]) - failures, failures);
    return failures == 0 ? 0 : 1;
}
