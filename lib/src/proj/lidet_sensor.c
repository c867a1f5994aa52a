/* SPDX-License-Identifier: MIT */
/* Sensor presets. Mirrored by tools/lidet_tools/sensors.py; tests/python/test_bindings_proj.py checks
 * that both give the same beam tables. Elevations in ring order, radians, float32-rounded. The integer
 * profiles of the same presets (microradians, millimetres) are in lidet_sensor_q.c. */
#include "lidet/lidet_sensor.h"
#include "internal/lidet_math.h"
#include "internal/lidet_str.h"

/* KITTI HDL-64E, measured on real KITTI scans (median elevation per ring recovered from scan order):
 * upper block +2.5 .. -7.7 deg in 32 equal steps, lower block -8.25 .. -23.5 deg in 32 steps.
 * Ring order top to bottom. */
static const float k_hdl64_elev_rad[64] = {
    0.04363323f,    0.0378905348f,  0.0321478397f,   0.0264051426f,   0.0206624456f,  0.0149197504f,
    0.00917705335f, 0.00343435747f, -0.00230833865f, -0.00805103499f, -0.0137937311f, -0.0195364282f,
    -0.0252791233f, -0.0310218204f, -0.0367645174f,  -0.0425072126f,  -0.0482499078f, -0.0539926067f,
    -0.0597353019f, -0.0654779971f, -0.071220696f,   -0.0769633874f,  -0.0827060863f, -0.0884487852f,
    -0.0941914767f, -0.0999341756f, -0.105676875f,   -0.111419566f,   -0.117162265f,  -0.122904956f,
    -0.128647655f,  -0.134390354f,  -0.143989667f,   -0.152575552f,   -0.161161453f,  -0.169747338f,
    -0.178333238f,  -0.186919138f,  -0.195505023f,   -0.204090923f,   -0.212676808f,  -0.221262708f,
    -0.229848608f,  -0.238434494f,  -0.247020394f,   -0.255606294f,   -0.264192164f,  -0.272778064f,
    -0.281363964f,  -0.289949864f,  -0.298535764f,   -0.307121634f,   -0.315707535f,  -0.324293435f,
    -0.332879335f,  -0.341465235f,  -0.350051105f,   -0.358637005f,   -0.367222905f,  -0.375808805f,
    -0.384394705f,  -0.392980576f,  -0.401566476f,   -0.410152376f,
};

/* Velodyne VLP-16: -15 .. +15 deg every 2 deg, ring 0 = lowest (velodyne_pointcloud's ring). */
static const float k_vlp16_elev_rad[16] = {
    -0.261799395f, -0.226892799f,  -0.191986218f, -0.157079637f, -0.122173049f, -0.0872664601f,
    -0.052359879f, -0.0174532924f, 0.0174532924f, 0.052359879f,  0.0872664601f, 0.122173049f,
    0.157079637f,  0.191986218f,   0.226892799f,  0.261799395f,
};

/* Velodyne VLP-32C: its real non-uniform table (dense near the horizon), ring 0 = lowest. */
static const float k_vlp32c_elev_rad[32] = {
    -0.436332315f,  -0.27295205f,    -0.19739674f,   -0.154339463f,  -0.126606181f,  -0.107302845f,
    -0.0930784121f, -0.0814545155f,  -0.0698131695f, -0.0640012249f, -0.0581718236f, -0.052359879f,
    -0.0465479307f, -0.0407185331f,  -0.0349065848f, -0.0290946383f, -0.0232652389f, -0.0174532924f,
    -0.0116413459f, -0.00581194647f, 0.0f,           0.00581194647f, 0.0116413459f,  0.0174532924f,
    0.0232652389f,  0.0290946383f,   0.0407185331f,  0.0581718236f,  0.0814545155f,  0.122173049f,
    0.180344865f,   0.261799395f,
};

/* Velodyne HDL-32E (nuScenes' sensor): -30.67 .. +10.67 deg every 4/3 deg as its manual lists them (two
 * decimals), ring 0 = lowest (velodyne_pointcloud's ring). */
static const float k_hdl32_elev_rad[32] = {
    -0.535292506f, -0.511905074f,  -0.488692194f,  -0.465479314f,  -0.442091912f,  -0.418879032f,
    -0.395666152f, -0.37227872f,   -0.34906584f,   -0.32585296f,   -0.302465558f,  -0.279252678f,
    -0.256039798f, -0.232652396f,  -0.209439516f,  -0.186226636f,  -0.162839219f,  -0.139626339f,
    -0.116413459f, -0.0930260494f, -0.0698131695f, -0.0466002896f, -0.0232128799f, 0.0f,
    0.0232128799f, 0.0466002896f,  0.0698131695f,  0.0930260494f,  0.116413459f,   0.139626339f,
    0.162839219f,  0.186226636f,
};

/* Hesai Pandar64 (PandaSet's sensor): the nominal channel elevations Hesai publishes for it, +14.882 .. -24.897 deg,
 * 0.167 deg apart between +2.028 and -6.061; ring r = channel r + 1, i.e. ring 0 = the top beam (Hesai's channel
 * order). On the PandaSet training frames this table keeps 86 % of the points in their own pixel, the hdl64 one
 * 60 % (docs/SENSORS.md). */
static const float k_pandar64_elev_rad[64] = {
    0.259739906f,    0.192544729f,   0.140656084f,    0.0882612988f,  0.0530580096f,  0.0353952758f,
    0.0324631259f,   0.0294611584f,  0.0265639108f,   0.0235793982f,  0.0206646975f,  0.0176801849f,
    0.0147654852f,   0.0117809726f,  0.00886627287f,  0.0058817598f,  0.00294960639f, 0.0f,
    -0.00294960639f, -0.0058817598f, -0.00886627287f, -0.0117809726f, -0.0147480322f, -0.0176801849f,
    -0.0206646975f,  -0.0235793982f, -0.0265639108f,  -0.0294611584f, -0.0324631259f, -0.0353952758f,
    -0.0383623354f,  -0.0412770361f, -0.0442615487f,  -0.0471238904f, -0.0501433089f, -0.0530580096f,
    -0.0560250692f,  -0.0589048639f, -0.0619242825f,  -0.0647866204f, -0.067788586f,  -0.0706858337f,
    -0.07367035f,    -0.0765326843f, -0.0795521066f,  -0.0823795423f, -0.0853815079f, -0.0882612988f,
    -0.0912632644f,  -0.0940907001f, -0.0971275717f,  -0.0999375507f, -0.102939516f,  -0.105784409f,
    -0.123272605f,   -0.140656084f,  -0.158126831f,   -0.172525793f,  -0.192544729f,  -0.209544227f,
    -0.226439014f,   -0.243124366f,  -0.329675257f,   -0.434534609f,
};

#define DEG(d) ((float)(d)*LIDET_DEG2RAD_F)

static const lidet_sensor_t k_presets[] = {
    {"hdl64", 64u, 2048u, k_hdl64_elev_rad, 0.0f, 0.0f, 1.73f, 120.0f},
    {"vlp16", 16u, 1800u, k_vlp16_elev_rad, 0.0f, 0.0f, 0.5f, 100.0f},
    {"vlp32c", 32u, 1800u, k_vlp32c_elev_rad, 0.0f, 0.0f, 1.0f, 200.0f},
    /* Ouster OS1: uniform +-22.5 deg; ring 0 = top beam (Ouster's convention) */
    {"os1-64", 64u, 2048u, 0, DEG(22.5), DEG(-22.5), 1.0f, 120.0f},
    {"os1-128", 128u, 2048u, 0, DEG(22.5), DEG(-22.5), 1.0f, 120.0f},
    /* HDL-32E at nuScenes' 20 Hz: a firing cycle every 46.08 us, 1085 per revolution; roof mount 1.84 m */
    {"hdl32", 32u, 1085u, k_hdl32_elev_rad, 0.0f, 0.0f, 1.84f, 100.0f},
    /* Ouster OS0 (+-45 deg), OS1 (+-22.5 deg, as os1-64), OS2 (+-11.25 deg), uniform, at the factory default
     * lidar mode 1024x10; ring 0 = top beam */
    {"os0-32", 32u, 1024u, 0, DEG(45.0), DEG(-45.0), 1.0f, 100.0f},
    {"os0-64", 64u, 1024u, 0, DEG(45.0), DEG(-45.0), 1.0f, 100.0f},
    {"os0-128", 128u, 1024u, 0, DEG(45.0), DEG(-45.0), 1.0f, 100.0f},
    {"os1-32", 32u, 1024u, 0, DEG(22.5), DEG(-22.5), 1.0f, 120.0f},
    {"os2-32", 32u, 1024u, 0, DEG(11.25), DEG(-11.25), 1.0f, 240.0f},
    {"os2-64", 64u, 1024u, 0, DEG(11.25), DEG(-11.25), 1.0f, 240.0f},
    {"os2-128", 128u, 1024u, 0, DEG(11.25), DEG(-11.25), 1.0f, 240.0f},
    /* Pandar64 at 10 Hz: 0.2 deg a column; PandaSet's roof mount 2.05 m (lidet_tools.real.pandaset) */
    {"pandar64", 64u, 1800u, k_pandar64_elev_rad, 0.0f, 0.0f, 2.05f, 200.0f},
};

#define N_PRESETS (sizeof(k_presets) / sizeof(k_presets[0]))

const lidet_sensor_t *lidet_sensor_find(const char *name)
{
    uint32_t i;
    if (name == 0)
    {
        return 0;
    }
    for (i = 0; i < N_PRESETS; ++i)
    {
        if (lidet__str_equal(name, k_presets[i].name))
        {
            return &k_presets[i];
        }
    }
    return 0;
}

const lidet_sensor_t *lidet_sensor_at(uint32_t index)
{
    return index < N_PRESETS ? &k_presets[index] : 0;
}
