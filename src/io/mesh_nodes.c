/*
** A mesh's nodes outside Gmsh (mesh_nodes.h).
*/
#include "io/mesh_nodes.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

typedef struct node_line {
    unsigned long long tag;
    long line;
} node_line;

static int cmp_node_line(const void *pa, const void *pb)
{
    const node_line *a = pa, *b = pb;
    if (a->tag != b->tag)
        return (a->tag > b->tag) - (a->tag < b->tag);
    return (a->line > b->line) - (a->line < b->line);
}

/* The next line of f into *line (its number counted); 0 at the end. */
static int next_line(FILE *f, char **line, size_t *cap, long *no)
{
    if (getline(line, cap, f) < 0)
        return 0;
    ++*no;
    return 1;
}

/* The node tags of an ASCII .msh file's $Nodes section (versions 2, 4.0 and 4.1) with their line
** numbers into *out; 0 when the file is not such a file or its section is malformed (Gmsh's reader
** then speaks for it), -1 when memory runs out. */
static long msh_node_tags(FILE *f, node_line **out)
{
    char *line = NULL;
    size_t cap = 0, n = 0, ncap = 0;
    long no = 0, nblocks = 1, total = 0;
    double version = 0;
    int type = 1;
    node_line *t = NULL;
    while (next_line(f, &line, &cap, &no) && strncmp(line, "$Nodes", 6) != 0)
        if (strncmp(line, "$MeshFormat", 11) == 0 && next_line(f, &line, &cap, &no))
            sscanf(line, "%lf %d", &version, &type);
    if (type != 0 || version < 2 || !next_line(f, &line, &cap, &no))
        goto done;
    if (version >= 4 ? sscanf(line, "%ld %ld", &nblocks, &total) != 2
                     : sscanf(line, "%ld", &total) != 1)
        goto done;
    for (long b = 0; b < nblocks; b++) {
        long k = total, dim, ent, param;
        if (version >= 4 && (!next_line(f, &line, &cap, &no) ||
                             sscanf(line, "%ld %ld %ld %ld", &dim, &ent, &param, &k) != 4 || k < 0))
            goto done;
        for (long i = 0; i < k; i++) {
            if (!next_line(f, &line, &cap, &no))
                goto done;
            if (n == ncap) {
                ncap = ncap ? 2 * ncap : 1024;
                node_line *q = realloc(t, ncap * sizeof *t);
                if (!q) {
                    free(t);
                    free(line);
                    return -1;
                }
                t = q;
            }
            t[n].tag = strtoull(line, NULL, 10);
            t[n++].line = no;
        }
        for (long i = 0; version >= 4.1 && i < k; i++) /* 4.1: the coordinates follow the tags */
            if (!next_line(f, &line, &cap, &no))
                goto done;
    }
    free(line);
    *out = t;
    return (long)n;
done:
    free(line);
    free(t);
    return 0;
}

/* A node an ASCII .msh file defines twice: Gmsh keeps the last one's coordinates without a word
** (and the elements that meant the first are joined to the second), so it is refused. */
cf_status cf_mesh_msh_nodes_once(const char *path, cf_error *err)
{
    size_t n = strlen(path);
    if (n < 4 || strcasecmp(path + n - 4, ".msh") != 0)
        return CF_OK;
    FILE *f = fopen(path, "rb");
    if (!f)
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot open mesh: %s", path, strerror(errno));
    node_line *t = NULL;
    long nt = msh_node_tags(f, &t);
    fclose(f);
    if (nt < 0)
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh", path);
    if (nt > 1) /* (qsort of no nodes would take t NULL) */
        qsort(t, (size_t)nt, sizeof *t, cmp_node_line);
    cf_status st = CF_OK;
    for (long i = 1; i < nt && st == CF_OK; i++)
        if (t[i].tag == t[i - 1].tag)
            st = cf_error_set(err, CF_E_DATA, "%s:%ld: node %llu is defined a second time (first "
                              "at line %ld)", path, t[i].line, t[i].tag, t[i - 1].line);
    free(t);
    return st;
}

typedef struct node_at {
    double x[3];
    uint32_t i;
} node_at;

static int cmp_node_at(const void *pa, const void *pb)
{
    const node_at *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->x[k] != b->x[k])
            return (a->x[k] > b->x[k]) - (a->x[k] < b->x[k]);
    return (a->i > b->i) - (a->i < b->i);
}

/* Two nodes of a mesh file at one point: the elements on either side are not joined (a crack the
** file does not show), so the mesh is refused naming both. */
cf_status cf_mesh_check_coincident(cf_mesh *m, const char *name, cf_error *err)
{
    node_at *o = malloc((m->nn + 1) * sizeof *o);
    if (!o) {
        cf_mesh_free(m);
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh", name);
    }
    for (size_t i = 0; i < m->nn; i++) {
        memcpy(o[i].x, m->X + 3 * i, sizeof o[i].x);
        o[i].i = (uint32_t)i;
    }
    qsort(o, m->nn, sizeof *o, cmp_node_at);
    cf_status st = CF_OK;
    for (size_t k = 1; k < m->nn && st == CF_OK; k++)
        if (memcmp(o[k].x, o[k - 1].x, sizeof o[k].x) == 0)
            st = cf_error_set(err, CF_E_DATA, "%s: nodes %lu and %lu are at the same point (%g, "
                              "%g, %g) mm: the elements on either side are not joined (merge "
                              "them in the file)", name, (unsigned long)m->id[o[k - 1].i],
                              (unsigned long)m->id[o[k].i], o[k].x[0], o[k].x[1], o[k].x[2]);
    free(o);
    if (st != CF_OK)
        cf_mesh_free(m);
    return st;
}

/* The mesh through the pipe from Gmsh's process: counts, then the arrays, then the groups. */
void cf_mesh_put(cf_isolate_buf *o, const cf_mesh *m)
{
    const uint64_t h[3] = {m->nn, m->nt, m->ngroups};
    cf_isolate_put(o, h, sizeof h);
    cf_isolate_put(o, m->X, 3 * m->nn * sizeof *m->X);
    cf_isolate_put(o, m->id, m->nn * sizeof *m->id);
    cf_isolate_put(o, m->tet, 4 * m->nt * sizeof *m->tet);
    cf_isolate_put(o, m->eid, m->nt * sizeof *m->eid);
    for (size_t g = 0; g < m->ngroups; g++) {
        const cf_mesh_group *G = &m->groups[g];
        const int64_t gh[3] = {G->dim, G->tag, (int64_t)G->nnodes};
        cf_isolate_put(o, gh, sizeof gh);
        cf_isolate_put(o, G->name, sizeof G->name);
        cf_isolate_put(o, G->nodes, G->nnodes * sizeof *G->nodes);
    }
}

/* Reads put_mesh's bytes into m; CF_E_INTERNAL when they are short or inconsistent. */
cf_status cf_mesh_get(cf_isolate_buf *in, const char *name, cf_mesh *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    uint64_t h[3];
    const size_t left = in->len - in->pos;
    if (!cf_isolate_get(in, h, sizeof h) || h[0] > left / 28 || h[1] > left / 24 ||
        h[2] > left / 24)
        goto bad;
    m->nn = (size_t)h[0];
    m->nt = (size_t)h[1];
    m->X = malloc((3 * m->nn + 1) * sizeof *m->X);
    m->id = malloc((m->nn + 1) * sizeof *m->id);
    m->tet = malloc((4 * m->nt + 1) * sizeof *m->tet);
    m->eid = malloc((m->nt + 1) * sizeof *m->eid);
    m->groups = calloc((size_t)h[2] + 1, sizeof *m->groups);
    if (!m->X || !m->id || !m->tet || !m->eid || !m->groups) {
        cf_mesh_free(m);
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh", name);
    }
    if (!cf_isolate_get(in, m->X, 3 * m->nn * sizeof *m->X) ||
        !cf_isolate_get(in, m->id, m->nn * sizeof *m->id) ||
        !cf_isolate_get(in, m->tet, 4 * m->nt * sizeof *m->tet) ||
        !cf_isolate_get(in, m->eid, m->nt * sizeof *m->eid))
        goto bad;
    for (size_t g = 0; g < h[2]; g++) {
        cf_mesh_group *G = &m->groups[m->ngroups++];
        int64_t gh[3];
        if (!cf_isolate_get(in, gh, sizeof gh) || !cf_isolate_get(in, G->name, sizeof G->name) ||
            gh[2] < 0 || (uint64_t)gh[2] > (in->len - in->pos) / sizeof *G->nodes)
            goto bad;
        G->dim = (int)gh[0];
        G->tag = (int)gh[1];
        G->nnodes = (size_t)gh[2];
        G->name[sizeof G->name - 1] = '\0';
        if (!(G->nodes = malloc((G->nnodes + 1) * sizeof *G->nodes))) {
            cf_mesh_free(m);
            return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh", name);
        }
        cf_isolate_get(in, G->nodes, G->nnodes * sizeof *G->nodes);
    }
    if (in->pos == in->len)
        return CF_OK;
bad:
    cf_mesh_free(m);
    return cf_error_set(err, CF_E_INTERNAL, "%s: the mesh from Gmsh's process is incomplete", name);
}

