/* SPDX-License-Identifier: MIT */
/* Command-line options of the host tools (the subcommands of `lidet`, lidet_bench_proj, lidet_bench_memory), parsed
 * with getopt_long (glibc's <getopt.h>: host tools only, never lib/).
 *
 * An option set is a table of long options declared once (cli_opt_t: name, flag or value, the set's own id, what
 * the value is) with the function that takes them into its struct. The shared sets: the sensor and the scan's
 * files (cli_common.c: cli_opts_sensor, cli_opts_io), a Velodyne calibration (cli_velodyne_calib.c:
 * cli_opts_velodyne_calib), a packet capture (cli_pcap.c: cli_opts_pcap, cli_opts_pcap_png_scan) and the detector
 * (cli_detect.c: cli_opts_det). A command lists the sets it accepts, the shared ones and its own, and
 * cli_options_parse builds one struct option table from them and runs getopt_long once over argv.
 *
 * The rules, the same in every command:
 * - options and positional arguments in any order; the positional arguments kept in their order; "--" ends the
 *   options (what follows is positional: a scan named "-x.bin");
 * - --name VALUE and --name=VALUE alike; a value is the next argument whatever it looks like (--out --json: a file
 *   named "--json");
 * - names exactly as declared: getopt_long's abbreviations (--sens for --sensor) are refused as unknown options, so
 *   that a new option never turns an abbreviation in someone's script ambiguous or into another option;
 * - the first problem stops the parse with one message naming the option: an unknown option (with a pointer to
 *   --help), a value missing at the end (what it would be), a value given to a flag (--json=1), or the set's own
 *   message for a bad value (what it expected and got).
 *
 * optstring starts with '-': getopt_long hands the positional arguments back in order (as option 1) instead of
 * permuting argv, so argv is left as it was and the parse is the same whether or not POSIXLY_CORRECT is set.
 * optind = 0 before each parse (glibc's full re-initialisation): a process may parse more than once. */
#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

#define MAX_OPTS 96
/* getopt_long's val of the table's entry k: ID_BASE + k, above every short option character */
#define ID_BASE 256

/* 1 when the argument arg ("--name" or "--name=value") spells name exactly (not an abbreviation of it) */
static int spells(const char *arg, const char *name)
{
    const size_t n = strcspn(arg + 2, "=");
    return strncmp(arg, "--", 2) == 0 && n == strlen(name) && strncmp(arg + 2, name, n) == 0;
}

int cli_options_parse(int argc, char **argv, const char *who, const cli_optset_t *sets, int n_sets,
                      char **pos, int *n_pos)
{
    struct option table[MAX_OPTS + 1];
    const cli_opt_t *entry[MAX_OPTS]; /* NULL: --help */
    int set_of[MAX_OPTS];
    int n = 0, s, c;
    *n_pos = 0;
    /* the table: --help, then the sets' options in the order given */
    table[0].name = "help";
    table[0].has_arg = no_argument;
    entry[n++] = NULL;
    for (s = 0; s < n_sets; ++s)
    {
        const cli_opt_t *e;
        for (e = sets[s].opts; e->name != NULL; ++e)
        {
            int k = 0;
            while (k < n && strcmp(table[k].name, e->name) != 0)
                ++k;
            if (k < n || n == MAX_OPTS)
            {
                fprintf(stderr, "%s: internal error: option --%s %s\n", who, e->name,
                        k < n ? "declared twice" : "past the option table's room");
                return CLI_PARSE_ERROR;
            }
            table[n].name = e->name;
            table[n].has_arg = e->has_arg;
            entry[n] = e;
            set_of[n++] = s;
        }
    }
    for (s = 0; s < n; ++s)
    {
        table[s].flag = NULL;
        table[s].val = ID_BASE + s;
    }
    memset(&table[n], 0, sizeof table[n]);

    opterr = 0; /* the messages are ours */
    optind = 0;
    for (;;)
    {
        /* the argument getopt_long looks at next: an option's own (its value may follow) */
        const char *arg = argv[optind > 0 ? optind : 1];
        int k;
        c = getopt_long(argc, argv, "-:h", table, NULL);
        if (c == -1)
            break;
        if (c == 1) /* a positional argument, in order */
        {
            pos[(*n_pos)++] = optarg;
            continue;
        }
        if (c == 'h')
            return CLI_PARSE_USAGE;
        k = (c == '?' || c == ':' ? optopt : c) - ID_BASE;
        if (k < 0 || k >= n || !spells(arg, table[k].name))
        {
            /* not declared, an abbreviation of one or more names, or an unknown short option */
            fprintf(stderr, "%s: unknown option %s (%s --help)\n", who, arg, who);
            return CLI_PARSE_ERROR;
        }
        if (c == ':')
        {
            if (entry[k]->value != NULL)
                fprintf(stderr, "%s: --%s needs a value (%s)\n", who, table[k].name, entry[k]->value);
            else
                fprintf(stderr, "%s: --%s needs a value\n", who, table[k].name);
            return CLI_PARSE_ERROR;
        }
        if (c == '?')
        {
            fprintf(stderr, "%s: --%s takes no value (got '%s')\n", who, table[k].name, arg);
            return CLI_PARSE_ERROR;
        }
        if (entry[k] == NULL)
            return CLI_PARSE_USAGE; /* --help */
        if (sets[set_of[k]].take(sets[set_of[k]].ctx, entry[k]->id, optarg) != 0)
            return CLI_PARSE_ERROR;
    }
    while (optind < argc) /* after "--" */
        pos[(*n_pos)++] = argv[optind++];
    return CLI_PARSE_OK;
}

cli_optset_t cli_optset(const cli_opt_t *opts, int (*take)(void *ctx, int id, const char *value), void *ctx)
{
    cli_optset_t s;
    s.opts = opts;
    s.take = take;
    s.ctx = ctx;
    return s;
}

int cli_list_take(void *ctx, int id, const char *value)
{
    cli_list_t *l = (cli_list_t *)ctx;
    (void)id;
    l->v[l->n++] = value;
    return 0;
}

enum
{
    OPT_BENCH_SENSOR,
    OPT_BENCH_REPEAT
};

const cli_opt_t cli_opts_bench[] = {{"sensor", required_argument, OPT_BENCH_SENSOR, "NAME: a sensor preset"},
                                    {"repeat", required_argument, OPT_BENCH_REPEAT, "N: runs per scan, >= 1"},
                                    {NULL, 0, 0, NULL}};

int cli_bench_take(void *ctx, int id, const char *v)
{
    cli_bench_opts_t *o = (cli_bench_opts_t *)ctx;
    char *end;
    long n;
    if (id == OPT_BENCH_SENSOR)
    {
        o->sensor = v;
        return 0;
    }
    n = strtol(v, &end, 10);
    if (end == v || *end != '\0' || n < 1 || n > 1000000)
    {
        fprintf(stderr, "%s: --repeat needs an integer in [1, 1000000], got '%s'\n", o->who, v);
        return 1;
    }
    o->repeat = (int)n;
    return 0;
}
