/* SPDX-License-Identifier: MIT */
#include "lidet/lidet.h"

const char *lidet_version(void)
{
    return LIDET_VERSION_STRING;
}

const char *lidet_status_str(lidet_status_t status)
{
#if LIDET_ENABLE_STATUS_STRINGS
    switch (status)
    {
    case LIDET_OK:
        return "LIDET_OK: success";
    case LIDET_TRUNCATED:
        return "LIDET_TRUNCATED: success, input beyond a capacity was dropped and counted";
    case LIDET_ERR_ARG:
        return "LIDET_ERR_ARG: NULL pointer or argument out of range";
    case LIDET_ERR_CONFIG:
        return "LIDET_ERR_CONFIG: configuration value out of range or inconsistent";
    case LIDET_ERR_BUFFER:
        return "LIDET_ERR_BUFFER: buffer or compile-time capacity too small";
    case LIDET_ERR_MODEL:
        return "LIDET_ERR_MODEL: model shape, format or version mismatch";
    case LIDET_ERR_STATE:
        return "LIDET_ERR_STATE: state not initialised";
    case LIDET_ERR_NOT_FOUND:
        return "LIDET_ERR_NOT_FOUND: no such item";
    default:
        return "unknown lidet status";
    }
#else
    (void)status;
    return "";
#endif
}
