/* SPDX-License-Identifier: MIT */
/* Integer sensor presets (lidet_sensor_q.h): the presets of lidet_sensor.c in microradians and millimetres,
 * the float values rounded to the nearest unit. tests/python/test_proj_q.py checks these literals against
 * tools/lidet_tools/sensors.py (Sensor.beam_elev_urad) and against the float presets. No float here. */
#include "lidet/lidet_sensor_q.h"
#include "internal/lidet_qmath.h"
#include "internal/lidet_str.h"

/* KITTI HDL-64E (see lidet_sensor.c): ring order top to bottom */
static const int32_t k_hdl64_elev_urad[64] = {
    43633,   37891,   32148,   26405,   20662,   14920,   9177,    3434,    -2308,   -8051,   -13794,
    -19536,  -25279,  -31022,  -36765,  -42507,  -48250,  -53993,  -59735,  -65478,  -71221,  -76963,
    -82706,  -88449,  -94191,  -99934,  -105677, -111420, -117162, -122905, -128648, -134390, -143990,
    -152576, -161161, -169747, -178333, -186919, -195505, -204091, -212677, -221263, -229849, -238434,
    -247020, -255606, -264192, -272778, -281364, -289950, -298536, -307122, -315708, -324293, -332879,
    -341465, -350051, -358637, -367223, -375809, -384395, -392981, -401566, -410152,
};

/* Velodyne VLP-16: -15 .. +15 deg every 2 deg, ring 0 = lowest */
static const int32_t k_vlp16_elev_urad[16] = {
    -261799, -226893, -191986, -157080, -122173, -87266, -52360, -17453,
    17453,   52360,   87266,   122173,  157080,  191986, 226893, 261799,
};

/* Velodyne VLP-32C, ring 0 = lowest */
static const int32_t k_vlp32c_elev_urad[32] = {
    -436332, -272952, -197397, -154339, -126606, -107303, -93078, -81455, -69813, -64001, -58172,
    -52360,  -46548,  -40719,  -34907,  -29095,  -23265,  -17453, -11641, -5812,  0,      5812,
    11641,   17453,   23265,   29095,   40719,   58172,   81455,  122173, 180345, 261799,
};

/* Velodyne HDL-32E (see lidet_sensor.c), ring 0 = lowest */
static const int32_t k_hdl32_elev_urad[32] = {
    -535292, -511905, -488692, -465479, -442092, -418879, -395666, -372279, -349066, -325853, -302466,
    -279253, -256040, -232652, -209440, -186227, -162839, -139626, -116413, -93026,  -69813,  -46600,
    -23213,  0,       23213,   46600,   69813,   93026,   116413,  139626,  162839,  186227,
};

/* Hesai Pandar64 (see lidet_sensor.c), ring 0 = the top beam */
static const int32_t k_pandar64_elev_urad[64] = {
    259740,  192545,  140656,  88261,   53058,   35395,   32463,   29461,   26564,   23579,   20665,
    17680,   14765,   11781,   8866,    5882,    2950,    0,       -2950,   -5882,   -8866,   -11781,
    -14748,  -17680,  -20665,  -23579,  -26564,  -29461,  -32463,  -35395,  -38362,  -41277,  -44262,
    -47124,  -50143,  -53058,  -56025,  -58905,  -61924,  -64787,  -67789,  -70686,  -73670,  -76533,
    -79552,  -82380,  -85382,  -88261,  -91263,  -94091,  -97128,  -99938,  -102940, -105784, -123273,
    -140656, -158127, -172526, -192545, -209544, -226439, -243124, -329675, -434535,
};

#define OS0_FOV_URAD 785398 /* 45 deg */
#define OS1_FOV_URAD 392699 /* 22.5 deg */
#define OS2_FOV_URAD 196350 /* 11.25 deg */

static const lidet_sensor_q_t k_presets_q[] = {
    {"hdl64", 64u, 2048u, k_hdl64_elev_urad, 0, 0, 1730, 120000},
    {"vlp16", 16u, 1800u, k_vlp16_elev_urad, 0, 0, 500, 100000},
    {"vlp32c", 32u, 1800u, k_vlp32c_elev_urad, 0, 0, 1000, 200000},
    {"os1-64", 64u, 2048u, 0, OS1_FOV_URAD, -OS1_FOV_URAD, 1000, 120000},
    {"os1-128", 128u, 2048u, 0, OS1_FOV_URAD, -OS1_FOV_URAD, 1000, 120000},
    {"hdl32", 32u, 1085u, k_hdl32_elev_urad, 0, 0, 1840, 100000},
    {"os0-32", 32u, 1024u, 0, OS0_FOV_URAD, -OS0_FOV_URAD, 1000, 100000},
    {"os0-64", 64u, 1024u, 0, OS0_FOV_URAD, -OS0_FOV_URAD, 1000, 100000},
    {"os0-128", 128u, 1024u, 0, OS0_FOV_URAD, -OS0_FOV_URAD, 1000, 100000},
    {"os1-32", 32u, 1024u, 0, OS1_FOV_URAD, -OS1_FOV_URAD, 1000, 120000},
    {"os2-32", 32u, 1024u, 0, OS2_FOV_URAD, -OS2_FOV_URAD, 1000, 240000},
    {"os2-64", 64u, 1024u, 0, OS2_FOV_URAD, -OS2_FOV_URAD, 1000, 240000},
    {"os2-128", 128u, 1024u, 0, OS2_FOV_URAD, -OS2_FOV_URAD, 1000, 240000},
    {"pandar64", 64u, 1800u, k_pandar64_elev_urad, 0, 0, 2050, 200000},
};

#define N_PRESETS_Q (sizeof(k_presets_q) / sizeof(k_presets_q[0]))

const lidet_sensor_q_t *lidet_sensor_q_find(const char *name)
{
    uint32_t i;
    if (name == 0)
    {
        return 0;
    }
    for (i = 0; i < N_PRESETS_Q; ++i)
    {
        if (lidet__str_equal(name, k_presets_q[i].name))
        {
            return &k_presets_q[i];
        }
    }
    return 0;
}

const lidet_sensor_q_t *lidet_sensor_q_at(uint32_t index)
{
    return index < N_PRESETS_Q ? &k_presets_q[index] : 0;
}

static int elev_ok(int32_t urad)
{
    return urad >= -LIDET_Q_MAX_ELEV_URAD && urad <= LIDET_Q_MAX_ELEV_URAD;
}

lidet_status_t lidet_sensor_q_elevations(const lidet_sensor_q_t *s, int32_t *out_urad)
{
    uint32_t r;
    if (s == 0 || out_urad == 0)
    {
        return LIDET_ERR_ARG;
    }
    if (s->n_rows == 0)
    {
        return LIDET_ERR_CONFIG;
    }
    if (s->n_rows > LIDET_MAX_ROWS)
    {
        return LIDET_ERR_BUFFER;
    }
    if (s->beam_elev_urad != 0)
    {
        for (r = 0; r < s->n_rows; ++r)
        {
            if (!elev_ok(s->beam_elev_urad[r]))
            {
                return LIDET_ERR_CONFIG;
            }
            out_urad[r] = s->beam_elev_urad[r];
        }
        return LIDET_OK;
    }
    if (!elev_ok(s->fov_up_urad) || !elev_ok(s->fov_down_urad) || s->fov_up_urad <= s->fov_down_urad)
    {
        return LIDET_ERR_CONFIG;
    }
    for (r = 0; r < s->n_rows; ++r)
    {
        const int64_t span = (int64_t)s->fov_up_urad - s->fov_down_urad;
        out_urad[r] = s->fov_up_urad -
                      (int32_t)lidet__q_div_round((int64_t)(2u * r + 1u) * span, 2 * (int64_t)s->n_rows);
    }
    return LIDET_OK;
}
