/* SPDX-License-Identifier: MIT */
/* `--velodyne-calib C` for every command (docs/VELODYNE_CALIBRATION.md): a Velodyne unit from its
 * factory calibration, Velodyne's db.xml / VeloView XML (boost-serialized <DB>: points_ / item / px, enabled_,
 * distLSB_; degrees and centimetres) read with libxml2, or velodyne_pointcloud's YAML (num_lasers, lasers,
 * distance_resolution; radians and metres) read with libyaml. The first character tells them apart ('<': XML).
 * The elevation table goes to cli_sensor_use_desc in ring order (the lasers sorted by elevation, lowest first, as
 * velodyne_pointcloud numbers its rings and lidet's Velodyne decoder and presets do). Each laser's id, rotational
 * and distance correction and the distance resolution are kept (cli_args_t.vcorr) for the packet decoder
 * (`--pcap`: cli_velodyne_calib_table, the rules and messages of tools/lidet_tools/velodyne.py calibration_table);
 * the other corrections are validated, not used.
 *
 * The rules, their order and the messages are those of tools/lidet_tools/sensors.py (load_velodyne_calibration):
 * a change here goes there too; tests/python/test_velodyne_calib.py compares the two message for message and
 * `--print-sensor` with sensors.description_json. Built without libxml2 (LIDET_HAVE_LIBXML2 unset) an XML
 * calibration, without libyaml (LIDET_HAVE_LIBYAML) a YAML one, exits with an error saying so. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

#ifdef LIDET_HAVE_LIBXML2
#include <libxml/hash.h>
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>
#endif
#ifdef LIDET_HAVE_LIBYAML
#include <yaml.h>
#endif

#define ERR_LEN 512
#define MAX_FILE_BYTES (16L << 20)
#define DEG2RAD_D (M_PI_D / 180.0)
#define RAD2DEG_D (180.0 / M_PI_D)
#define VEL_MOUNT_HEIGHT_M 1.0  /* not in the file: --mount-height overrides it */
#define VEL_MAX_RANGE_M 100.0   /* not in the file: informational */
#define VEL_RESOLUTION_M 0.002  /* the distance resolution when the file gives none */
#define YAML_MAX_DEPTH 32       /* deeper nesting is refused */
#define N_OPTIONAL 7

/* the lasers as read: the enabled ones in the file's order */
typedef struct
{
    int n;
    int entry[LIDET_MAX_ROWS];  /* its entry: points_ item (XML), lasers index (YAML) */
    double vert[LIDET_MAX_ROWS]; /* the elevation as read: degrees (XML), radians (YAML) */
    double rad[LIDET_MAX_ROWS];  /* the elevation in radians */
    int id[LIDET_MAX_ROWS];      /* id_ / laser_id */
    /* the rotational correction in radians (XML: its degrees x pi / 180, numpy's radians) */
    double rot_rad[LIDET_MAX_ROWS];
    /* the distance correction in metres (XML: its centimetres x 0.01), 0 when absent */
    double dist_m[LIDET_MAX_ROWS];
    double res_m; /* the distance resolution, metres (VEL_RESOLUTION_M when not given) */
} vel_lasers_t;

static int bad(char *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, ERR_LEN, fmt, ap);
    va_end(ap);
    return 1;
}

#if defined(LIDET_HAVE_LIBXML2) || defined(LIDET_HAVE_LIBYAML)
/* a decimal number, the whole of s[0, len): [-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)? (sensors.py:
 * _CAL_NUMBER); its value (strtod: correctly rounded, overflow to +-inf) in *x. 0, or 1 when it is not one. */
static int cal_number(const char *s, size_t len, double *x)
{
    size_t i = 0, d0;
    char buf[400];
    if (i < len && (s[i] == '+' || s[i] == '-'))
        ++i;
    d0 = i;
    while (i < len && s[i] >= '0' && s[i] <= '9')
        ++i;
    if (i == d0)
    {
        /* no integer part: a dot and at least one digit */
        if (i >= len || s[i] != '.')
            return 1;
        d0 = ++i;
        while (i < len && s[i] >= '0' && s[i] <= '9')
            ++i;
        if (i == d0)
            return 1;
    }
    else if (i < len && s[i] == '.')
    {
        ++i;
        while (i < len && s[i] >= '0' && s[i] <= '9')
            ++i;
    }
    if (i < len && (s[i] == 'e' || s[i] == 'E'))
    {
        ++i;
        if (i < len && (s[i] == '+' || s[i] == '-'))
            ++i;
        d0 = i;
        while (i < len && s[i] >= '0' && s[i] <= '9')
            ++i;
        if (i == d0)
            return 1;
    }
    if (i != len)
        return 1;
    if (len < sizeof buf)
    {
        memcpy(buf, s, len);
        buf[len] = '\0';
        *x = strtod(buf, NULL);
    }
    else
    {
        char *big = (char *)malloc(len + 1u);
        if (big == NULL)
            return 1;
        memcpy(big, s, len);
        big[len] = '\0';
        *x = strtod(big, NULL);
        free(big);
    }
    return 0;
}

/* the index of the first laser whose single-precision radians equal an earlier one's (*j: that one), or -1 */
static int first_same(const vel_lasers_t *L, int *j)
{
    int i, k;
    for (i = 1; i < L->n; ++i)
        for (k = 0; k < i; ++k)
            if ((float)L->rad[k] == (float)L->rad[i])
            {
                *j = k;
                return i;
            }
    return -1;
}
#endif

/* ====================================== db.xml / VeloView XML (libxml2) ====================================== */
#ifdef LIDET_HAVE_LIBXML2

/* db.xml's element names of the optional corrections (sensors.py: _VELODYNE_OPTIONAL) */
static const char *const k_xml_optional[N_OPTIONAL] = {"distCorrection_",       "distCorrectionX_",
                                                       "distCorrectionY_",      "vertOffsetCorrection_",
                                                       "horizOffsetCorrection_", "focalDistance_",
                                                       "focalSlope_"};

static int is_elem(const xmlNode *c, const char *name)
{
    return c->type == XML_ELEMENT_NODE && c->ns == NULL && strcmp((const char *)c->name, name) == 0;
}

/* the one child element named name (*out NULL when absent): 0, or 1 when given twice */
static int xml_child(const xmlNode *parent, const char *name, const char *what, const xmlNode **out, char *err)
{
    const xmlNode *c;
    *out = NULL;
    for (c = parent->children; c != NULL; c = c->next)
    {
        if (!is_elem(c, name))
            continue;
        if (*out != NULL)
            return bad(err, "%s: given twice", what);
        *out = c;
    }
    return 0;
}

/* an element's text as a number (sensors.py: _xml_number): no child element, the text trimmed of XML white space */
static int xml_number(const xmlNode *el, const char *what, double *x, char *err)
{
    const xmlNode *c;
    char *text = NULL;
    size_t len = 0, b = 0, e;
    int rc;
    for (c = el->children; c != NULL; c = c->next)
    {
        if (c->type == XML_ELEMENT_NODE)
        {
            free(text);
            return bad(err, "%s: not a number", what);
        }
        if ((c->type == XML_TEXT_NODE || c->type == XML_CDATA_SECTION_NODE) && c->content != NULL)
        {
            const size_t k = strlen((const char *)c->content);
            char *t = (char *)realloc(text, len + k + 1u);
            if (t == NULL)
            {
                free(text);
                return bad(err, "%s: out of memory", what);
            }
            text = t;
            memcpy(text + len, c->content, k + 1u);
            len += k;
        }
    }
    e = len;
    while (b < e && (text[b] == ' ' || text[b] == '\t' || text[b] == '\r' || text[b] == '\n'))
        ++b;
    while (e > b && (text[e - 1] == ' ' || text[e - 1] == '\t' || text[e - 1] == '\r' || text[e - 1] == '\n'))
        --e;
    rc = text == NULL || cal_number(text + b, e - b, x) != 0;
    free(text);
    if (rc)
        return bad(err, "%s: not a number", what);
    if (!isfinite(*x))
        return bad(err, "%s: not a finite number", what);
    return 0;
}

static int xml_integer(const xmlNode *el, const char *what, double lo, double hi, long *out, char *err)
{
    double x = 0.0;
    if (xml_number(el, what, &x, err) != 0)
        return 1;
    if (x != floor(x))
        return bad(err, "%s: expected an integer, got %g", what, x);
    if (x < lo || x > hi)
        return bad(err, "%s: %g is outside [%.0f, %.0f]", what, x, lo, hi);
    *out = (long)x;
    return 0;
}

/* the number of <item> children of a boost-serialized list; its <count>, when given, must say as much */
static int xml_items(const xmlNode *parent, const char *name, int *n_items, char *err)
{
    const xmlNode *c, *count;
    char w[64];
    long k = 0;
    int n = 0;
    for (c = parent->children; c != NULL; c = c->next)
        n += is_elem(c, "item");
    snprintf(w, sizeof w, "\"%s.count\"", name);
    if (xml_child(parent, "count", w, &count, err) != 0)
        return 1;
    if (count != NULL)
    {
        if (xml_integer(count, w, 0.0, 1000000.0, &k, err) != 0)
            return 1;
        if (k != (long)n)
            return bad(err, "\"%s.count\": %ld but \"%s\" has %d items", name, k, name, n);
    }
    *n_items = n;
    return 0;
}

/* the parser's message of a document it could not read, without its trailing newline */
static void xml_error(const xmlParserCtxt *ctxt, char *err)
{
    const xmlError *e = xmlCtxtGetLastError((void *)ctxt);
    char msg[256];
    size_t k;
    snprintf(msg, sizeof msg, "%s", e != NULL && e->message != NULL ? e->message : "unknown error");
    k = strlen(msg);
    while (k > 0 && (msg[k - 1] == '\n' || msg[k - 1] == ' '))
        msg[--k] = '\0';
    bad(err, "not valid XML (line %d: %s)", e != NULL ? e->line : 0, msg);
}

/* set by refuse_entity: the document declares an entity */
static int g_entity_declared;

/* an entity declaration (general, parameter or unparsed): refused where the parser meets it, as defusedxml does
 * (no entity is ever expanded: billion laughs and external entities alike) */
static void refuse_entity(void *ctx, const xmlChar *name, int type, const xmlChar *public_id,
                          const xmlChar *system_id, xmlChar *content)
{
    xmlParserCtxt *ctxt = (xmlParserCtxt *)ctx;
    (void)name, (void)type, (void)public_id, (void)system_id, (void)content;
    g_entity_declared = 1;
    xmlStopParser(ctxt);
}

static void refuse_unparsed_entity(void *ctx, const xmlChar *name, const xmlChar *public_id,
                                   const xmlChar *system_id, const xmlChar *notation)
{
    refuse_entity(ctx, name, 0, public_id, system_id, NULL);
    (void)notation;
}

static int has_entities(const xmlDoc *doc)
{
    const xmlDtd *d = doc->intSubset;
    return d != NULL && ((d->entities != NULL && xmlHashSize((xmlHashTablePtr)d->entities) > 0) ||
                         (d->pentities != NULL && xmlHashSize((xmlHashTablePtr)d->pentities) > 0));
}

/* the lasers of a db.xml (sensors.py: _velodyne_xml), the doc parsed; enabled, seen: room for every <item> of
 * enabled_ and points_ (each list's item count) */
static int read_xml_doc(const xmlNode *db, vel_lasers_t *L, unsigned char *enabled, int *seen, char *err)
{
    const xmlNode *el, *en, *pts, *c;
    int n_enabled_items = 0, n_items = 0, n, k, i, j;
    long id_hi;
    char w[64], f[96];
    double x = 0.0;
    if (xml_child(db, "distLSB_", "\"distLSB_\"", &el, err) != 0)
        return 1;
    if (el != NULL)
    {
        if (xml_number(el, "\"distLSB_\"", &x, err) != 0)
            return 1;
        if (!(x > 0.0 && x <= 100.0))
            return bad(err, "\"distLSB_\": %g is outside (0, 100] (centimetres)", x);
        L->res_m = x * 0.01;
    }
    if (xml_child(db, "enabled_", "\"enabled_\"", &en, err) != 0)
        return 1;
    if (en != NULL)
    {
        if (xml_items(en, "enabled_", &n_enabled_items, err) != 0)
            return 1;
        i = 0;
        for (c = en->children; c != NULL; c = c->next)
        {
            if (!is_elem(c, "item"))
                continue;
            snprintf(w, sizeof w, "\"enabled_\"[%d]", i);
            if (xml_number(c, w, &x, err) != 0)
                return 1;
            if (x != 0.0 && x != 1.0)
                return bad(err, "%s: expected 0 or 1, got %g", w, x);
            enabled[i++] = (unsigned char)(x == 1.0);
        }
    }
    if (xml_child(db, "points_", "\"points_\"", &pts, err) != 0)
        return 1;
    if (pts == NULL)
        return bad(err, "\"points_\": missing: not a Velodyne calibration (db.xml)?");
    if (xml_items(pts, "points_", &n_items, err) != 0)
        return 1;
    if (en != NULL)
    {
        for (n = 0, i = 0; i < n_enabled_items; ++i)
            n += enabled[i];
        if (n < 1 || n > LIDET_MAX_ROWS)
            return bad(err, "\"enabled_\": %d lasers enabled, outside [1, %d] (LIDET_MAX_ROWS)", n, LIDET_MAX_ROWS);
        id_hi = n_enabled_items - 1;
    }
    else
    {
        n = n_items;
        if (n < 1 || n > LIDET_MAX_ROWS)
            return bad(err, "\"points_\": %d lasers, outside [1, %d] (LIDET_MAX_ROWS)", n, LIDET_MAX_ROWS);
        id_hi = n_items - 1;
    }
    L->n = 0;
    k = 0;
    for (c = pts->children; c != NULL; c = c->next)
    {
        static const char *const tags[2] = {"vertCorrection_", "rotCorrection_"};
        static const double lim[2] = {90.0, 180.0};
        const xmlNode *px;
        double v[2] = {0.0, 0.0}, dist = 0.0;
        long id = 0;
        int t;
        if (!is_elem(c, "item"))
            continue;
        snprintf(w, sizeof w, "\"points_\"[%d]", k);
        snprintf(f, sizeof f, "%s.px", w);
        if (xml_child(c, "px", f, &px, err) != 0)
            return 1;
        if (px == NULL)
            return bad(err, "%s: no \"px\"", w);
        snprintf(f, sizeof f, "%s.id_", w);
        if (xml_child(px, "id_", f, &el, err) != 0)
            return 1;
        if (el == NULL)
            return bad(err, "%s: missing", f);
        if (xml_integer(el, f, 0.0, (double)id_hi, &id, err) != 0)
            return 1;
        if (seen[id] != 0)
            return bad(err, "%s: %ld given twice (also \"points_\"[%d])", f, id, seen[id] - 1);
        seen[id] = ++k;
        if (en != NULL && !enabled[id])
            continue; /* a laser the unit does not have (a db.xml lists 64) */
        for (t = 0; t < 2; ++t)
        {
            snprintf(f, sizeof f, "%s.%s", w, tags[t]);
            if (xml_child(px, tags[t], f, &el, err) != 0)
                return 1;
            if (el == NULL)
                return bad(err, "%s: missing", f);
            if (xml_number(el, f, &v[t], err) != 0)
                return 1;
            if (!(v[t] > -lim[t] && v[t] < lim[t]))
                return bad(err, "%s: %g deg is outside (%g, %g)", f, v[t], -lim[t], lim[t]);
        }
        for (t = 0; t < N_OPTIONAL; ++t) /* read and validated, not used (docs/VELODYNE_CALIBRATION.md) */
        {
            snprintf(f, sizeof f, "%s.%s", w, k_xml_optional[t]);
            if (xml_child(px, k_xml_optional[t], f, &el, err) != 0)
                return 1;
            if (el != NULL && xml_number(el, f, &x, err) != 0)
                return 1;
            if (el != NULL && t == 0)
                dist = x * 0.01; /* distCorrection_, cm -> m (sensors.py: _VELODYNE_OPTIONAL's scale) */
        }
        L->entry[L->n] = k - 1;
        L->vert[L->n] = v[0];
        L->rad[L->n] = v[0] * DEG2RAD_D;
        L->id[L->n] = (int)id;
        L->rot_rad[L->n] = v[1] * DEG2RAD_D;
        L->dist_m[L->n] = dist;
        ++L->n;
    }
    for (i = 0; en != NULL && i < n_enabled_items; ++i)
        if (enabled[i] && seen[i] == 0)
            return bad(err, "\"enabled_\"[%d]: laser %d is enabled, but \"points_\" has no px with id_ %d", i, i, i);
    i = first_same(L, &j);
    if (i >= 0)
        return bad(err,
                   "\"points_\"[%d].vertCorrection_: the same elevation as \"points_\"[%d] (%g deg): beams must be "
                   "distinct",
                   L->entry[i], L->entry[j], L->vert[i]);
    return 0;
}

/* the number of <item> children of a DB member (0 when absent) */
static size_t n_items_of(const xmlNode *db, const char *name)
{
    const xmlNode *c, *e;
    size_t n = 0;
    for (c = db->children; c != NULL; c = c->next)
        if (is_elem(c, name))
            for (e = c->children; e != NULL; e = e->next)
                n += is_elem(e, "item");
    return n;
}

static int read_xml(const char *buf, size_t size, vel_lasers_t *L, char *err)
{
    xmlParserCtxt *ctxt = xmlNewParserCtxt();
    xmlDoc *doc;
    const xmlNode *root, *db = NULL;
    int rc;
    g_entity_declared = 0;
    if (ctxt == NULL || ctxt->sax == NULL)
    {
        xmlFreeParserCtxt(ctxt);
        return bad(err, "not valid XML (out of memory)");
    }
    ctxt->sax->entityDecl = refuse_entity;
    ctxt->sax->unparsedEntityDecl = refuse_unparsed_entity;
    /* no entity substitution (XML_PARSE_NOENT unset), no DTD loading, no network; entity declarations refused */
    doc = xmlCtxtReadMemory(ctxt, buf, (int)size, NULL, NULL,
                            XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
    if (g_entity_declared || doc == NULL)
    {
        if (g_entity_declared)
            bad(err, "not valid XML for a calibration (entity declarations are refused)");
        else
            xml_error(ctxt, err);
        xmlFreeDoc(doc);
        xmlFreeParserCtxt(ctxt);
        return 1;
    }
    xmlFreeParserCtxt(ctxt);
    root = xmlDocGetRootElement(doc);
    if (has_entities(doc))
        rc = bad(err, "not valid XML for a calibration (entity declarations are refused)");
    else if (root != NULL && is_elem(root, "DB"))
        rc = 0, db = root;
    else if (root != NULL && is_elem(root, "boost_serialization"))
        rc = xml_child(root, "DB", "\"DB\"", &db, err);
    else
        rc = 0;
    if (rc == 0 && db == NULL)
        rc = bad(err, "\"DB\": missing (<boost_serialization><DB>...</DB>): not a Velodyne calibration (db.xml)?");
    if (rc == 0)
    {
        /* a laser id indexes enabled_'s items (or points_'s): room for the larger list */
        const size_t ne = n_items_of(db, "enabled_"), np = n_items_of(db, "points_");
        const size_t room = (ne > np ? ne : np) + 1u;
        unsigned char *enabled = (unsigned char *)calloc(room, 1);
        int *seen = (int *)calloc(room, sizeof *seen);
        rc = enabled == NULL || seen == NULL ? bad(err, "out of memory") : read_xml_doc(db, L, enabled, seen, err);
        free(enabled);
        free(seen);
    }
    xmlFreeDoc(doc);
    return rc;
}

#endif /* LIDET_HAVE_LIBXML2 */

/* ================================= velodyne_pointcloud's YAML (libyaml) ================================= */
#ifdef LIDET_HAVE_LIBYAML

/* velodyne_pointcloud's keys of the optional corrections (sensors.py: _VELODYNE_OPTIONAL) */
static const char *const k_yaml_optional[N_OPTIONAL] = {
    "dist_correction",         "dist_correction_x", "dist_correction_y", "vert_offset_correction",
    "horiz_offset_correction", "focal_distance",    "focal_slope"};

enum
{
    Y_SCALAR,
    Y_SEQ,
    Y_MAP
};

/* the document as a tree (sensors.py: _yaml_tree); a mapping's kids are key, value, key, value ... */
typedef struct ynode
{
    int kind;
    int plain; /* a plain scalar (resolved as null, boolean, number or string), else a string */
    char *s;
    size_t len;
    struct ynode **kids;
    size_t n, cap;
} ynode_t;

static void y_free(ynode_t *v)
{
    size_t i;
    if (v == NULL)
        return;
    for (i = 0; i < v->n; ++i)
        y_free(v->kids[i]);
    free(v->kids);
    free(v->s);
    free(v);
}

static int y_push(ynode_t *c, ynode_t *v)
{
    if (c->n == c->cap)
    {
        const size_t cap = c->cap ? 2 * c->cap : 8;
        ynode_t **k = (ynode_t **)realloc(c->kids, cap * sizeof *k);
        if (k == NULL)
            return 1;
        c->kids = k;
        c->cap = cap;
    }
    c->kids[c->n++] = v;
    return 0;
}

/* a member's name in messages (sensors.py: _yaml_path): "key" at the top, parent.key below, parent[i] in a list;
 * key NULL: the index. A new string (NULL when out of memory). */
static char *y_path(const char *parent, const char *key, size_t klen, size_t index)
{
    const size_t n = strlen(parent) + (key != NULL ? klen : 24) + 8;
    char *p = (char *)malloc(n);
    if (p == NULL)
        return NULL;
    if (key == NULL)
        snprintf(p, n, "%s[%zu]", parent, index);
    else if (parent[0] == '\0')
        snprintf(p, n, "\"%.*s\"", (int)klen, key);
    else
        snprintf(p, n, "%s.%.*s", parent, (int)klen, key);
    return p;
}

typedef struct
{
    ynode_t *c;
    char *path;
    int have_key; /* a mapping whose last key waits for its value */
} yframe_t;

/* builds the tree from the parser's events: one document, no alias, scalar keys given once, at most YAML_MAX_DEPTH
 * levels. 0 and *root (NULL: no document), or 1 with the message. */
static int y_build(yaml_parser_t *p, ynode_t **root, char *err)
{
    yframe_t stack[YAML_MAX_DEPTH];
    int depth = 0, docs = 0, done = 0, rc = 0, k;
    *root = NULL;
    while (!done && rc == 0)
    {
        yaml_event_t ev;
        ynode_t *v = NULL;
        int line;
        if (!yaml_parser_parse(p, &ev))
        {
            if (p->error == YAML_READER_ERROR)
                rc = bad(err, "not valid YAML (byte %zu: %s)", p->problem_offset,
                         p->problem != NULL ? p->problem : "?");
            else if (p->error == YAML_SCANNER_ERROR || p->error == YAML_PARSER_ERROR)
                rc = bad(err, "not valid YAML (line %zu column %zu: %s)", p->problem_mark.line + 1,
                         p->problem_mark.column + 1, p->problem != NULL ? p->problem : "?");
            else
                rc = bad(err, "not valid YAML (%s)", p->problem != NULL ? p->problem : "out of memory");
            break;
        }
        line = (int)ev.start_mark.line + 1;
        switch (ev.type)
        {
        case YAML_STREAM_END_EVENT:
            done = 1;
            break;
        case YAML_DOCUMENT_START_EVENT:
            if (++docs > 1)
                rc = bad(err, "the file must hold one YAML document");
            break;
        case YAML_ALIAS_EVENT:
            rc = bad(err, "YAML aliases are not supported (line %d)", line);
            break;
        case YAML_SCALAR_EVENT:
        case YAML_SEQUENCE_START_EVENT:
        case YAML_MAPPING_START_EVENT:
            if (ev.type != YAML_SCALAR_EVENT && depth >= YAML_MAX_DEPTH)
            {
                rc = bad(err, "nested deeper than %d levels (line %d)", YAML_MAX_DEPTH, line);
                break;
            }
            v = (ynode_t *)calloc(1, sizeof *v);
            if (v == NULL)
            {
                rc = bad(err, "out of memory");
                break;
            }
            if (ev.type == YAML_SCALAR_EVENT)
            {
                v->kind = Y_SCALAR;
                v->plain = ev.data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
                v->len = ev.data.scalar.length;
                v->s = (char *)malloc(v->len + 1u);
                if (v->s == NULL)
                {
                    free(v);
                    rc = bad(err, "out of memory");
                    break;
                }
                memcpy(v->s, ev.data.scalar.value, v->len);
                v->s[v->len] = '\0';
            }
            else
            {
                v->kind = ev.type == YAML_SEQUENCE_START_EVENT ? Y_SEQ : Y_MAP;
            }
            if (depth == 0)
            {
                *root = v;
            }
            else
            {
                yframe_t *t = &stack[depth - 1];
                if (t->c->kind == Y_MAP && !t->have_key)
                {
                    size_t i;
                    if (v->kind != Y_SCALAR)
                    {
                        y_free(v);
                        rc = bad(err, "a mapping key must be a scalar (line %d)", line);
                        break;
                    }
                    for (i = 0; i < t->c->n; i += 2)
                    {
                        const ynode_t *key = t->c->kids[i];
                        if (key->len == v->len && memcmp(key->s, v->s, v->len) == 0)
                        {
                            char *path = y_path(t->path, v->s, v->len, 0);
                            rc = bad(err, "%s: given twice", path != NULL ? path : "?");
                            free(path);
                            break;
                        }
                    }
                    if (rc != 0)
                    {
                        y_free(v);
                        break;
                    }
                }
                if (y_push(t->c, v) != 0)
                {
                    y_free(v);
                    rc = bad(err, "out of memory");
                    break;
                }
                if (t->c->kind == Y_MAP)
                    t->have_key = !t->have_key;
            }
            if (v->kind != Y_SCALAR)
            {
                char *path;
                if (depth == 0)
                {
                    path = (char *)calloc(1, 1);
                }
                else
                {
                    const yframe_t *t = &stack[depth - 1];
                    /* the container just pushed: a list's item i, or a mapping's value of the key before it */
                    path = t->c->kind == Y_SEQ
                               ? y_path(t->path, NULL, 0, t->c->n - 1u)
                               : y_path(t->path, t->c->kids[t->c->n - 2u]->s, t->c->kids[t->c->n - 2u]->len, 0);
                }
                if (path == NULL)
                {
                    rc = bad(err, "out of memory");
                    break;
                }
                stack[depth].c = v;
                stack[depth].path = path;
                stack[depth].have_key = 0;
                ++depth;
            }
            break;
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT:
            --depth;
            free(stack[depth].path);
            break;
        default:
            break;
        }
        yaml_event_delete(&ev);
    }
    for (k = 0; k < depth; ++k)
        free(stack[k].path);
    if (rc != 0)
    {
        y_free(*root);
        *root = NULL;
    }
    return rc;
}

enum
{
    YV_NULL,
    YV_TRUE,
    YV_FALSE,
    YV_NUM,
    YV_STR,
    YV_SEQ,
    YV_MAP
};

static int s_is(const ynode_t *v, const char *a, const char *b, const char *c)
{
    return strcmp(v->s, a) == 0 || strcmp(v->s, b) == 0 || strcmp(v->s, c) == 0;
}

/* what a node is as lidet reads it (sensors.py: _yaml_value); YV_NUM: *x its value */
static int y_value(const ynode_t *v, double *x)
{
    size_t o;
    if (v->kind == Y_SEQ)
        return YV_SEQ;
    if (v->kind == Y_MAP)
        return YV_MAP;
    if (!v->plain || strlen(v->s) != v->len)
        return YV_STR;
    if (v->len == 0 || strcmp(v->s, "~") == 0 || s_is(v, "null", "Null", "NULL"))
        return YV_NULL;
    if (s_is(v, "true", "True", "TRUE"))
        return YV_TRUE;
    if (s_is(v, "false", "False", "FALSE"))
        return YV_FALSE;
    if (cal_number(v->s, v->len, x) == 0)
        return YV_NUM;
    o = (v->s[0] == '+' || v->s[0] == '-') ? 1u : 0u;
    if (strcmp(v->s + o, ".inf") == 0 || strcmp(v->s + o, ".Inf") == 0 || strcmp(v->s + o, ".INF") == 0)
    {
        *x = v->s[0] == '-' ? -INFINITY : INFINITY;
        return YV_NUM;
    }
    if (strcmp(v->s, ".nan") == 0 || strcmp(v->s, ".NaN") == 0 || strcmp(v->s, ".NAN") == 0)
    {
        *x = NAN;
        return YV_NUM;
    }
    return YV_STR;
}

static const char *y_kind(const ynode_t *v)
{
    double x = 0.0;
    switch (y_value(v, &x))
    {
    case YV_NULL:
        return "null";
    case YV_TRUE:
        return "true";
    case YV_FALSE:
        return "false";
    case YV_NUM:
        return "a number";
    case YV_SEQ:
        return "a list";
    case YV_MAP:
        return "a mapping";
    default:
        return "a string";
    }
}

/* a mapping's value for key (NULL when absent) */
static const ynode_t *y_get(const ynode_t *map, const char *key)
{
    size_t i;
    const size_t len = strlen(key);
    for (i = 0; i + 1 < map->n; i += 2)
        if (map->kids[i]->len == len && memcmp(map->kids[i]->s, key, len) == 0)
            return map->kids[i + 1];
    return NULL;
}

static int y_number(const ynode_t *v, const char *what, double *x, char *err)
{
    if (y_value(v, x) != YV_NUM)
        return bad(err, "%s: expected a number, got %s", what, y_kind(v));
    if (!isfinite(*x))
        return bad(err, "%s: not a finite number", what);
    return 0;
}

static int y_integer(const ynode_t *v, const char *what, double lo, double hi, const char *macro, long *out,
                     char *err)
{
    double x = 0.0;
    if (y_value(v, &x) != YV_NUM)
        return bad(err, "%s: expected an integer, got %s", what, y_kind(v));
    if (!isfinite(x))
        return bad(err, "%s: not a finite number", what);
    if (x != floor(x))
        return bad(err, "%s: expected an integer, got %g", what, x);
    if (x < lo || x > hi)
        return bad(err, "%s: %g is outside [%.0f, %.0f]%s%s%s", what, x, lo, hi, macro[0] ? " (" : "", macro,
                   macro[0] ? ")" : "");
    *out = (long)x;
    return 0;
}

/* the lasers of velodyne_pointcloud's YAML (sensors.py: _velodyne_yaml) */
static int read_yaml_tree(const ynode_t *root, vel_lasers_t *L, char *err)
{
    const ynode_t *lasers, *v;
    int seen[LIDET_MAX_ROWS]; /* the entry of each id, + 1 */
    long n = 0;
    size_t i;
    int j, k;
    char w[48], f[96];
    double x = 0.0;
    if (root == NULL || root->kind != Y_MAP)
        return bad(err, "the file must hold one YAML mapping");
    lasers = y_get(root, "lasers");
    if (lasers == NULL)
        return bad(err, "\"lasers\": missing: not a velodyne_pointcloud calibration?");
    if (lasers->kind != Y_SEQ)
        return bad(err, "\"lasers\": expected a list, got %s", y_kind(lasers));
    v = y_get(root, "num_lasers");
    if (v == NULL)
        return bad(err, "\"num_lasers\": missing");
    if (y_integer(v, "\"num_lasers\"", 1.0, (double)LIDET_MAX_ROWS, "LIDET_MAX_ROWS", &n, err) != 0)
        return 1;
    if ((size_t)n != lasers->n)
        return bad(err, "\"num_lasers\": %ld but \"lasers\" has %zu entries", n, lasers->n);
    v = y_get(root, "distance_resolution");
    if (v != NULL)
    {
        if (y_number(v, "\"distance_resolution\"", &x, err) != 0)
            return 1;
        if (!(x > 0.0 && x <= 1.0))
            return bad(err, "\"distance_resolution\": %g is outside (0, 1] (metres)", x);
        L->res_m = x;
    }
    memset(seen, 0, sizeof seen);
    L->n = 0;
    for (i = 0; i < lasers->n; ++i)
    {
        static const char *const keys[2] = {"vert_correction", "rot_correction"};
        static const double lim[2] = {90.0, 180.0};
        const ynode_t *las = lasers->kids[i];
        double val[2] = {0.0, 0.0}, dist = 0.0;
        long id = 0;
        int t;
        snprintf(w, sizeof w, "\"lasers\"[%zu]", i);
        if (las->kind != Y_MAP)
            return bad(err, "%s: expected a mapping, got %s", w, y_kind(las));
        snprintf(f, sizeof f, "%s.laser_id", w);
        v = y_get(las, "laser_id");
        if (v == NULL)
            return bad(err, "%s: missing", f);
        if (y_integer(v, f, 0.0, (double)(n - 1), "", &id, err) != 0)
            return 1;
        if (seen[id] != 0)
            return bad(err, "%s: %ld given twice (also \"lasers\"[%d])", f, id, seen[id] - 1);
        seen[id] = (int)i + 1;
        for (t = 0; t < 2; ++t)
        {
            double d;
            snprintf(f, sizeof f, "%s.%s", w, keys[t]);
            v = y_get(las, keys[t]);
            if (v == NULL)
                return bad(err, "%s: missing", f);
            if (y_number(v, f, &val[t], err) != 0)
                return 1;
            d = val[t] * RAD2DEG_D;
            if (!(d > -lim[t] && d < lim[t]))
                return bad(err, "%s: %g rad (%g deg) is outside (%g, %g) deg", f, val[t], d, -lim[t], lim[t]);
        }
        for (t = 0; t < N_OPTIONAL; ++t) /* read and validated, not used (docs/VELODYNE_CALIBRATION.md) */
        {
            snprintf(f, sizeof f, "%s.%s", w, k_yaml_optional[t]);
            v = y_get(las, k_yaml_optional[t]);
            if (v != NULL && y_number(v, f, &x, err) != 0)
                return 1;
            if (v != NULL && t == 0)
                dist = x; /* dist_correction, metres */
        }
        L->entry[L->n] = (int)i;
        L->vert[L->n] = val[0];
        L->rad[L->n] = val[0];
        L->id[L->n] = (int)id;
        L->rot_rad[L->n] = val[1];
        L->dist_m[L->n] = dist;
        ++L->n;
    }
    k = first_same(L, &j);
    if (k >= 0)
        return bad(err,
                   "\"lasers\"[%d].vert_correction: the same elevation as \"lasers\"[%d] (%g rad): beams must be "
                   "distinct",
                   L->entry[k], L->entry[j], L->vert[k]);
    return 0;
}

static int read_yaml(const char *buf, size_t size, vel_lasers_t *L, char *err)
{
    yaml_parser_t p;
    ynode_t *root = NULL;
    int rc;
    if (!yaml_parser_initialize(&p))
        return bad(err, "not valid YAML (out of memory)");
    yaml_parser_set_input_string(&p, (const unsigned char *)buf, size);
    rc = y_build(&p, &root, err);
    yaml_parser_delete(&p);
    if (rc == 0)
        rc = read_yaml_tree(root, L, err);
    y_free(root);
    return rc;
}

#endif /* LIDET_HAVE_LIBYAML */

/* ============================================ the command's sensor ============================================ */

/* the options (cli_options.c; every command that takes a sensor): --velodyne-calib C, --cols N */
enum
{
    OPT_VELODYNE_CALIB,
    OPT_COLS
};

const cli_opt_t cli_opts_velodyne_calib[] = {
    {"velodyne-calib", required_argument, OPT_VELODYNE_CALIB, "C: a Velodyne calibration, db.xml or YAML"},
    {"cols", required_argument, OPT_COLS, "N: columns per revolution"},
    {NULL, 0, 0, NULL}};

int cli_velodyne_calib_take(void *ctx, int id, const char *v)
{
    cli_args_t *a = (cli_args_t *)ctx;
    char *end;
    long n;
    if (id == OPT_VELODYNE_CALIB)
    {
        a->velodyne_calib = v;
        return 0;
    }
    n = strtol(v, &end, 10);
    if (end == v || *end != '\0' || n < 8 || n > LIDET_MAX_COLS)
    {
        fprintf(stderr, "lidet %s: --cols needs an integer in [8, %d] (LIDET_MAX_COLS), got '%s'\n", cli_cmd,
                LIDET_MAX_COLS, v);
        return 1;
    }
    a->velodyne_cols = n;
    return 0;
}

/* reads the whole file (at most 16 MiB); the caller frees *buf */
static int read_file(const char *path, char **buf, size_t *size, char *err)
{
    struct stat st;
    FILE *f;
    *buf = NULL;
    if (stat(path, &st) != 0)
        return bad(err, "cannot read: %s", strerror(errno));
    if (!S_ISREG(st.st_mode))
        return bad(err, "cannot read: not a regular file");
    if (st.st_size > MAX_FILE_BYTES)
        return bad(err, "larger than %ld MiB: not a Velodyne calibration", MAX_FILE_BYTES >> 20);
    *size = (size_t)st.st_size;
    *buf = (char *)malloc(*size + 1u);
    f = fopen(path, "rb");
    if (*buf == NULL || f == NULL || fread(*buf, 1, *size, f) != *size)
    {
        const int e = errno;
        if (f != NULL)
            fclose(f);
        free(*buf);
        *buf = NULL;
        return bad(err, "cannot read: %s", f == NULL ? strerror(e) : "read error");
    }
    fclose(f);
    (*buf)[*size] = '\0';
    return 0;
}

/* 1: an XML calibration (the first character after a UTF-8 byte-order mark and white space is '<'; sensors.py:
 * velodyne_calibration_kind) */
static int is_xml(const char *buf, size_t size)
{
    size_t i = size >= 3 && memcmp(buf, "\xef\xbb\xbf", 3) == 0 ? 3u : 0u;
    while (i < size && (buf[i] == ' ' || buf[i] == '\t' || buf[i] == '\r' || buf[i] == '\n'))
        ++i;
    return i < size && buf[i] == '<';
}

int cli_velodyne_calib_load(cli_args_t *a, const char *cmd)
{
    static vel_lasers_t L;
    cli_sensor_desc_t *d = &a->desc;
    const char *path = a->velodyne_calib;
    char err[ERR_LEN];
    const char *missing = NULL;
    char *buf = NULL;
    size_t size = 0;
    int rc, xml = 0, order[LIDET_MAX_ROWS], i, j;
    memset(d, 0, sizeof *d);
    memset(&a->vcorr, 0, sizeof a->vcorr);
    memset(&L, 0, sizeof L);
    L.res_m = VEL_RESOLUTION_M;
    err[0] = '\0';
    rc = read_file(path, &buf, &size, err);
    if (rc == 0)
    {
        xml = is_xml(buf, size);
        if (xml)
        {
#ifdef LIDET_HAVE_LIBXML2
            rc = read_xml(buf, size, &L, err);
#else
            missing = "libxml2";
#endif
        }
        else
        {
#ifdef LIDET_HAVE_LIBYAML
            rc = read_yaml(buf, size, &L, err);
#else
            missing = "libyaml";
#endif
        }
    }
    free(buf);
    if (missing != NULL)
    {
        fprintf(stderr,
                "lidet %s: %s: --velodyne-calib needs %s to read this %s calibration, and this lidet was built "
                "without it (apt-get install %s-dev, then reconfigure and rebuild)\n",
                cmd, path, missing, xml ? "XML" : "YAML", missing);
        return 1;
    }
    if (rc != 0)
    {
        fprintf(stderr, "lidet %s: %s: %s\n", cmd, path, err);
        return 1;
    }
    /* ring order: the lasers sorted by elevation, lowest first (distinct: any sort gives the same) */
    for (i = 0; i < L.n; ++i)
    {
        for (j = i; j > 0 && L.rad[order[j - 1]] > L.rad[i]; --j)
            order[j] = order[j - 1];
        order[j] = i;
    }
    snprintf(d->name, sizeof d->name, "velodyne-%d", L.n);
    d->rows = (uint16_t)L.n;
    d->cols = (uint16_t)(a->velodyne_cols > 0                   ? a->velodyne_cols
                         : (L.n == 64 ? 2048 : 1800) <= LIDET_MAX_COLS ? (L.n == 64 ? 2048 : 1800)
                                                                       : LIDET_MAX_COLS);
    d->have_rad = 1;
    for (i = 0; i < L.n; ++i)
    {
        const int k = order[i];
        d->elev_rad_d[i] = L.rad[k];
        d->elev_deg[i] = xml ? L.vert[k] : L.rad[k] * RAD2DEG_D;
        a->vcorr.laser_id[i] = L.id[k];
        a->vcorr.rot_rad[i] = L.rot_rad[k];
        a->vcorr.dist_m[i] = L.dist_m[k];
    }
    a->vcorr.n = L.n;
    a->vcorr.distance_resolution_m = L.res_m;
    d->mount_height_m = VEL_MOUNT_HEIGHT_M; /* --mount-height overrides it (cli_parse) */
    d->max_range_m = VEL_MAX_RANGE_M;
    cli_sensor_use_desc(a);
    return 0;
}

/* ========================================= the packet decoder's table ========================================= */

/* velodyne.py's name of a model (N_LASERS, DIST_UNIT_MM), its lasers and its packets' distance unit (mm) */
static const char *vel_model_name(int model, uint32_t *n, uint32_t *unit_mm)
{
    *unit_mm = model == LIDET_VELODYNE_VLP32C ? 4u : 2u;
    *n = lidet_velodyne_n_rings((lidet_velodyne_model_t)model);
    switch (model)
    {
    case LIDET_VELODYNE_HDL32E:
        return "hdl32e";
    case LIDET_VELODYNE_VLP16:
        return "vlp16";
    case LIDET_VELODYNE_VLP32C:
        return "vlp32c";
    case LIDET_VELODYNE_HDL64E:
        return "hdl64e";
    default:
        return NULL;
    }
}

int cli_velodyne_calib_table(const cli_args_t *a, int model, lidet_velodyne_calib_t *t, char *err, size_t err_len)
{
    const cli_velodyne_corr_t *v = &a->vcorr;
    uint32_t n = 0, unit = 0;
    const char *name = vel_model_name(model, &n, &unit);
    unsigned char seen[LIDET_VELODYNE_MAX_LASERS];
    char res[64];
    int i;
    memset(t, 0, sizeof *t);
    if (name == NULL || n == 0u)
    {
        snprintf(err, err_len, "a calibration needs the model (one of hdl32e, vlp16, vlp32c, hdl64e)");
        return 1;
    }
    if (v->n != (int)n)
    {
        snprintf(err, err_len, "calibration: %d lasers, the %s has %u", v->n, name, n);
        return 1;
    }
    memset(seen, 0, sizeof seen);
    for (i = 0; i < v->n; ++i)
    {
        if (v->laser_id[i] < 0 || v->laser_id[i] >= (int)n || seen[v->laser_id[i]])
        {
            snprintf(err, err_len, "calibration: the laser ids are not 0 .. %u", n - 1u);
            return 1;
        }
        seen[v->laser_id[i]] = 1;
    }
    /* round(res x 1000, 6) as Python rounds: the correctly rounded 6-decimal value (glibc's printf rounds alike) */
    snprintf(res, sizeof res, "%.6f", v->distance_resolution_m * 1000.0);
    if (strtod(res, NULL) != (double)unit)
    {
        snprintf(err, err_len, "calibration: distance resolution %g mm, the %s's packets count %u mm",
                 v->distance_resolution_m * 1000.0, name, unit);
        return 1;
    }
    t->n_lasers = n;
    for (i = 0; i < v->n; ++i)
    {
        /* calibration_table: the elevation in degrees as the Sensor holds it (desc.elev_deg: XML's as read, YAML's
         * radians x 180 / pi), numpy's degrees (x * (180 / pi)), the metres x 1000; np.round: half to even (rint) */
        const double vert = rint(a->desc.elev_deg[i] * 1000.0);
        const double rot = rint(v->rot_rad[i] * RAD2DEG_D * 100.0);
        const double dist = rint(v->dist_m[i] * 1000.0);
        lidet_velodyne_laser_calib_t *l = &t->laser[v->laser_id[i]];
        if (fabs(dist) > 32767.0)
        {
            snprintf(err, err_len, "calibration: a distance correction beyond +-32.767 m");
            return 1;
        }
        /* the loaders keep elevations in (-90, 90) deg and rotations in (-180, 180) deg: these fit (an elevation
         * rounded to +-90 000 mdeg is refused by lidet_velodyne_init) */
        l->vert_mdeg = (int32_t)vert;
        l->rot_cdeg = (int16_t)rot;
        l->dist_mm = (int16_t)dist;
    }
    return 0;
}
