/* SPDX-License-Identifier: MIT */
/* Replays inputs through a libFuzzer harness without libFuzzer (any compiler; the gcc and sanitizer
 * builds run the committed corpora and crash regressions this way): each argument is a file or a folder
 * whose regular files are all replayed. Exits non-zero when an argument cannot be read or holds no input;
 * a failing input aborts inside the harness (FZ_CHECK, a sanitizer). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int replay_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    uint8_t *buf;
    if (f == NULL || fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0)
    {
        fprintf(stderr, "replay: cannot read %s\n", path);
        if (f != NULL)
        {
            fclose(f);
        }
        return -1;
    }
    buf = (uint8_t *)malloc((size_t)n + 1u);
    if (buf == NULL || fread(buf, 1, (size_t)n, f) != (size_t)n)
    {
        fprintf(stderr, "replay: cannot read %s\n", path);
        free(buf);
        fclose(f);
        return -1;
    }
    fclose(f);
    LLVMFuzzerTestOneInput(buf, (size_t)n);
    free(buf);
    return 1;
}

int main(int argc, char **argv)
{
    int i, total = 0;
    for (i = 1; i < argc; ++i)
    {
        struct stat sb;
        if (stat(argv[i], &sb) != 0)
        {
            fprintf(stderr, "replay: %s does not exist\n", argv[i]);
            return 2;
        }
        if (S_ISDIR(sb.st_mode))
        {
            DIR *d = opendir(argv[i]);
            struct dirent *e;
            if (d == NULL)
            {
                fprintf(stderr, "replay: cannot open %s\n", argv[i]);
                return 2;
            }
            while ((e = readdir(d)) != NULL)
            {
                char path[4096];
                struct stat fb;
                snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
                if (e->d_name[0] == '.' || stat(path, &fb) != 0 || !S_ISREG(fb.st_mode))
                {
                    continue;
                }
                if (replay_file(path) < 0)
                {
                    closedir(d);
                    return 2;
                }
                ++total;
            }
            closedir(d);
        }
        else
        {
            if (replay_file(argv[i]) < 0)
            {
                return 2;
            }
            ++total;
        }
    }
    printf("replay: %d inputs, no failure\n", total);
    return total > 0 ? 0 : 3;
}
