/* SPDX-License-Identifier: MIT */
/* `lidet`: the host command-line tool. One subcommand per pipeline stage (ports/host/cli_<stage>.c). */
#include <string.h>

#include "cli.h"

typedef struct
{
    const char *name;
    int (*fn)(int argc, char **argv);
    const char *help;
} cli_cmd_t;

static const cli_cmd_t k_cmds[] = {
    {"project", cli_project, "spherical projection: points -> range image"},
    {"ground", cli_ground, "ground segmentation: points -> ground mask per point"},
    {"cluster", cli_cluster, "depth clustering + proposals: non-ground pixels -> clusters"},
    {"detect", cli_detect, "the whole detector: points -> road users with 3D boxes"},
    {"track", cli_track, "detector + tracker over a sequence of scans: ids, velocities (docs/TRACKING.md)"},
};

int main(int argc, char **argv)
{
    size_t i;
    if (argc >= 2 && strcmp(argv[1], "--version") == 0)
    {
        printf("lidet %s\n", lidet_version());
        return 0;
    }
    if (argc >= 2)
    {
        for (i = 0; i < sizeof k_cmds / sizeof k_cmds[0]; ++i)
        {
            if (strcmp(argv[1], k_cmds[i].name) == 0)
            {
                cli_cmd = k_cmds[i].name;
                /* argv[0] the subcommand's name, as getopt_long takes it (cli_options.c) */
                return k_cmds[i].fn(argc - 1, argv + 1);
            }
        }
        fprintf(stderr, "lidet: unknown command '%s'\n", argv[1]);
    }
    fprintf(stderr, "usage: lidet COMMAND SCAN.bin [options]   (lidet COMMAND --help; lidet track SCANS... | DIR)\n"
                    "commands:\n");
    for (i = 0; i < sizeof k_cmds / sizeof k_cmds[0]; ++i)
    {
        fprintf(stderr, "  %-10s %s\n", k_cmds[i].name, k_cmds[i].help);
    }
    return 1;
}
