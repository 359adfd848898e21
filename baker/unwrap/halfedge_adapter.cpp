/*
 * The OpenMesh adapter (C header: halfedge_adapter.h). Welded triangles go into an
 * OpenMesh::TriMesh_ArrayKernelT in input order (OpenMesh is deterministic given the add
 * order). add_face refuses a triangle on a complex edge (an edge with two triangles
 * already), a winding flip (a triangle already runs the edge the same way), a closed
 * vertex fan ("complex vertex") or fans it cannot relink. Every refused triangle is added
 * again in a second pass, in input order, on copies of some of its vertices at the same
 * positions, as OpenMesh's own importers do (ImporterT::add_face copies all three). Here
 * copies are shared: each vertex has a chain of copies and a re-added triangle takes the
 * first copy whose fan still has a gap, so refused triangles that neighbour each other
 * stay neighbours (a wall standing on a floor's inner edges moves to copies of the floor's
 * vertices as a whole); and only the corners that must be copied are, the set keeping
 * the most adjacency first. Three new vertices are the last resort: add_face cannot
 * refuse those. Then welded edges that 3+ triangles share are marked seams on every copy,
 * so which two of them add_face paired does not decide a chart, and the adjacency is read
 * from the half-edge structure once and exported.
 *
 * ::omerr() is one process-wide OpenMesh stream that writes std::cerr; printing from a
 * library is not ours to do. The first build gives that stream, once (std::call_once), a
 * stream buffer that counts each message into the counts of the build running on the
 * writing thread (a thread_local pointer) and passes messages written outside any build
 * on to where they went before. Lines are gathered per thread, so this is thread-safe; it
 * is process-wide and never undone (a restore could race with a build on another thread).
 */
#include "halfedge_adapter.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <exception>
#include <ostream>
#include <mutex>
#include <new>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

namespace {

typedef OpenMesh::TriMesh_ArrayKernelT<> Mesh;
typedef OpenMesh::VertexHandle VH;
typedef OpenMesh::FaceHandle FH;
typedef OpenMesh::HalfedgeHandle HH;

const uint32_t none = UINT32_MAX;

thread_local lmb_topology_counts *tl_counts = nullptr; /* the build running on this thread */

/* ::omerr()'s stream buffer from the first build on: whole lines, gathered per thread, are
 * counted into the build running on the writing thread, or handed to the buffer it had
 * before (OpenMesh's multiplexer, which writes std::cerr) when none runs there. */
class omerr_counter : public std::streambuf {
public:
    explicit omerr_counter(std::streambuf *previous) : previous_(previous) {}

protected:
    int_type overflow(int_type c) override
    {
        if (traits_type::eq_int_type(c, traits_type::eof()))
            return traits_type::not_eof(c);
        line().push_back(traits_type::to_char_type(c));
        if (c == '\n')
            end_line();
        return c;
    }

    std::streamsize xsputn(const char *s, std::streamsize n) override
    {
        for (std::streamsize i = 0; i < n; i++)
            overflow(traits_type::to_int_type(s[i]));
        return n;
    }

    int sync() override
    {
        if (!line().empty())
            end_line();
        return 0;
    }

private:
    static std::string &line()
    {
        static thread_local std::string text;
        return text;
    }

    void end_line()
    {
        std::string &text = line();
        lmb_topology_counts *c = tl_counts;
        if (!c) {
            if (previous_) {
                previous_->sputn(text.data(), (std::streamsize)text.size());
                previous_->pubsync();
            }
        } else if (text.find("complex vertex") != std::string::npos) {
            c->om_complex_vertex++;
        } else if (text.find("complex edge") != std::string::npos) {
            c->om_complex_edge++;
        } else if (text.find("re-linking failed") != std::string::npos) {
            c->om_relink_failed++;
        } else {
            c->om_other++;
        }
        text.clear();
    }

    std::streambuf *previous_;
};

/* Once per process: ::omerr() writes into an omerr_counter. The counter is never freed
 * (OpenMesh's stream may be written until exit) and never taken out again (that could race
 * with a build on another thread). OpenMesh's disconnect() is not used: it leaks its target. */
void route_omerr_once()
{
    static std::once_flag once;
    static omerr_counter *counter = nullptr;
    std::call_once(once, [] {
        counter = new omerr_counter(omerr().rdbuf());
        omerr().rdbuf(counter);
    });
}

/* Points ::omerr() messages of this thread at counts for the guard's lifetime. */
struct count_scope {
    explicit count_scope(lmb_topology_counts *c) { tl_counts = c; }
    ~count_scope() { tl_counts = nullptr; }
};

/* Whether halfedge a -> b already has a triangle; *two: its opposite has one as well. */
bool edge_taken(const Mesh &m, VH a, VH b, bool *two)
{
    HH h = m.find_halfedge(a, b);
    if (!h.is_valid() || m.is_boundary(h))
        return false;
    *two = !m.is_boundary(m.opposite_halfedge_handle(h));
    return true;
}

/* Counts why add_face refused (v0, v1, v2), looking at the mesh as add_face did (OpenMesh
 * names a closed vertex first where both apply; an edge is the more telling cause). */
void count_refusal(const Mesh &m, const VH v[3], lmb_topology_counts *c)
{
    bool complex = false, flipped = false;
    for (int k = 0; k < 3; k++) {
        bool two = false;
        if (edge_taken(m, v[k], v[(k + 1) % 3], &two))
            (two ? complex : flipped) = true;
    }
    if (complex)
        c->complex_edge_faces++;
    else if (flipped)
        c->flipped_faces++;
    else
        c->vertex_faces++;
}

/* The half-edge mesh under construction. Every vertex at one welded position is on one
 * chain: the welded vertex, then its duplicates in order of creation (next[]). */
struct builder {
    Mesh m;
    std::vector<int> next;       /* per mesh vertex: the next copy at its position, or -1 */
    std::vector<uint32_t> input; /* per OpenMesh face: the input triangle */

    VH add_copy(VH v)
    {
        Mesh::Point p = m.point(v); /* a copy: add_vertex may move the point array */
        VH d = m.add_vertex(p);
        int last = v.idx();
        while (next[(size_t)last] >= 0)
            last = next[(size_t)last];
        next[(size_t)last] = d.idx();
        next.push_back(-1);
        return d;
    }

    /* The copy of v that a re-added triangle should use: the first duplicate whose fans
     * still have a gap (duplicates are shared, so refused neighbours stay neighbours), or
     * an invalid handle for a new one. */
    VH layer(VH v) const
    {
        for (int c = next[(size_t)v.idx()]; c >= 0; c = next[(size_t)c])
            if (m.is_boundary(VH(c)))
                return VH(c);
        return VH();
    }

    /* Re-adds refused triangle v[] on copies of the vertices in one subset S of its corners:
     * of the subsets whose copies have gaps and whose edges are free, those gaining the
     * most adjacency (edges with a triangle across) first, then smaller ones. When all fail
     * (OpenMesh could not relink a fan), three new vertices: add_face cannot refuse those. */
    FH readd(const VH v[3], VH w[3])
    {
        struct option {
            int subset, across, size;
        } opts[7];
        int n = 0;
        for (int s = 1; s < 8; s++) {
            VH x[3];
            bool ok = true;
            int across = 0;
            for (int k = 0; k < 3; k++) {
                x[k] = (s >> k & 1) ? layer(v[k]) : v[k];
                ok = ok && (!x[k].is_valid() || m.is_boundary(x[k]));
            }
            for (int k = 0; ok && k < 3; k++) {
                VH a = x[k], b = x[(k + 1) % 3];
                bool two = false;
                if (!a.is_valid() || !b.is_valid())
                    continue;
                ok = !edge_taken(m, a, b, &two);
                HH back = m.find_halfedge(b, a);
                across += back.is_valid() && !m.is_boundary(back);
            }
            if (ok)
                opts[n++] = {s, across, (s & 1) + (s >> 1 & 1) + (s >> 2 & 1)};
        }
        std::stable_sort(opts, opts + n, [](const option &a, const option &b) {
            return a.across != b.across ? a.across > b.across : a.size < b.size;
        });
        for (int i = 0; i < n; i++) {
            for (int k = 0; k < 3; k++) {
                w[k] = v[k];
                if (opts[i].subset >> k & 1) {
                    w[k] = layer(v[k]);
                    if (!w[k].is_valid())
                        w[k] = add_copy(v[k]);
                }
            }
            FH f = m.add_face(w[0], w[1], w[2]);
            if (f.is_valid())
                return f;
        }
        for (int k = 0; k < 3; k++)
            w[k] = add_copy(v[k]);
        return m.add_face(w[0], w[1], w[2]);
    }

    /* Input triangles on the welded edge (a, b), over every copy of both ends. */
    uint32_t edge_faces(VH a, VH b) const
    {
        uint32_t n = 0;
        for (int i = a.idx(); i >= 0; i = next[(size_t)i])
            for (int j = b.idx(); j >= 0; j = next[(size_t)j]) {
                HH h = m.find_halfedge(VH(i), VH(j));
                if (h.is_valid())
                    n += !m.is_boundary(h) + !m.is_boundary(m.opposite_halfedge_handle(h));
            }
        return n;
    }

    /* Marks the welded edge (a, b) a seam on every copy of it. */
    void mark_seam(VH a, VH b, OpenMesh::EPropHandleT<bool> seam)
    {
        for (int i = a.idx(); i >= 0; i = next[(size_t)i])
            for (int j = b.idx(); j >= 0; j = next[(size_t)j]) {
                HH h = m.find_halfedge(VH(i), VH(j));
                if (h.is_valid())
                    m.property(seam, m.edge_handle(h)) = true;
            }
    }
};

lmb_status build(const lmb_halfedge_input *in, uint32_t *corner, uint32_t *neighbor, uint32_t *mesh_vertices,
                 lmb_topology_counts *c, lmb_error *err)
{
    const char *name = in->name ? in->name : "mesh";
    builder b;
    Mesh &m = b.m;
    m.reserve(in->vertex_count, 3 * (size_t)in->face_count / 2 + 3, in->face_count);
    b.next.assign(in->vertex_count, -1);
    b.input.reserve(in->face_count);
    for (uint32_t i = 0; i < in->vertex_count; i++) {
        const float *p = in->positions + 3 * (size_t)i;
        m.add_vertex(Mesh::Point(p[0], p[1], p[2]));
    }
    /* pass 1: every triangle in input order on the welded vertices */
    std::vector<uint32_t> refused;
    for (uint32_t f = 0; f < in->face_count; f++) {
        const uint32_t *t = in->faces + 3 * (size_t)f;
        for (int k = 0; k < 3; k++) {
            corner[3 * (size_t)f + k] = t[k];
            neighbor[3 * (size_t)f + k] = none;
        }
        /* a positive area implies three distinct welded vertices; checked all the same */
        if (in->skip[f] || t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
            continue;
        VH v[3] = {VH((int)t[0]), VH((int)t[1]), VH((int)t[2])};
        if (m.add_face(v[0], v[1], v[2]).is_valid()) {
            b.input.push_back(f);
        } else {
            count_refusal(m, v, c);
            refused.push_back(f);
        }
    }
    /* pass 2: the refused ones in input order, on duplicated vertices */
    for (uint32_t f : refused) {
        const uint32_t *t = in->faces + 3 * (size_t)f;
        VH v[3] = {VH((int)t[0]), VH((int)t[1]), VH((int)t[2])}, w[3];
        if (!b.readd(v, w).is_valid())
            return lmb_error_set(err, LMB_ERR_INTERNAL,
                                 "unwrap: mesh '%s': OpenMesh refused triangle %u even on new vertices", name, f);
        for (int k = 0; k < 3; k++)
            corner[3 * (size_t)f + k] = (uint32_t)w[k].idx();
        b.input.push_back(f);
    }
    if (b.input.size() != m.n_faces())
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: mesh '%s': OpenMesh numbered its faces unexpectedly",
                             name);
    /* seams: welded edges of refused triangles that 3+ input triangles share (every such
     * edge has one: a mesh edge holds two) */
    OpenMesh::EPropHandleT<bool> seam;
    m.add_property(seam);
    for (const auto &e : m.edges())
        m.property(seam, e) = false;
    std::vector<std::pair<uint32_t, uint32_t>> nonmanifold;
    for (uint32_t f : refused)
        for (int k = 0; k < 3; k++) {
            uint32_t a = in->faces[3 * (size_t)f + k], e = in->faces[3 * (size_t)f + (k + 1) % 3];
            if (b.edge_faces(VH((int)a), VH((int)e)) < 3)
                continue;
            b.mark_seam(VH((int)a), VH((int)e), seam);
            nonmanifold.push_back(std::make_pair(a < e ? a : e, a < e ? e : a));
        }
    std::sort(nonmanifold.begin(), nonmanifold.end());
    c->nonmanifold_edges = (uint32_t)(std::unique(nonmanifold.begin(), nonmanifold.end()) - nonmanifold.begin());
    /* adjacency per corner: the halfedge leaving corner k's vertex, its opposite's face */
    for (const auto &fh : m.faces()) {
        uint32_t f = b.input[(size_t)fh.idx()];
        const uint32_t *cv = corner + 3 * (size_t)f;
        for (const auto &h : m.fh_range(fh)) {
            uint32_t from = (uint32_t)m.from_vertex_handle(h).idx();
            int k = from == cv[0] ? 0 : from == cv[1] ? 1 : 2;
            FH across = m.face_handle(m.opposite_halfedge_handle(h));
            if (across.is_valid() && !m.property(seam, m.edge_handle(h)))
                neighbor[3 * (size_t)f + k] = b.input[(size_t)across.idx()];
        }
    }
    for (const auto &vh : m.vertices()) {
        c->bowtie_vertices += !m.is_manifold(vh);
        c->duplicated_vertices += (uint32_t)vh.idx() >= in->vertex_count && !m.is_isolated(vh);
    }
    *mesh_vertices = (uint32_t)m.n_vertices();
    return LMB_OK;
}

} // namespace

extern "C" lmb_status lmb_halfedge_build(const lmb_halfedge_input *in, uint32_t *corner_vertex, uint32_t *neighbor,
                                         uint32_t *mesh_vertices, lmb_topology_counts *counts, lmb_error *err)
{
    const char *name = in->name ? in->name : "mesh";
    *counts = lmb_topology_counts();
    *mesh_vertices = in->vertex_count;
    if (in->vertex_count > (uint32_t)INT32_MAX / 2 || in->face_count > (uint32_t)INT32_MAX / 4)
        return lmb_error_set(err, LMB_ERR_INPUT, "unwrap: mesh '%s' has more vertices or triangles than OpenMesh indexes",
                             name);
    try {
        route_omerr_once();
        count_scope scope(counts);
        return build(in, corner_vertex, neighbor, mesh_vertices, counts, err);
    } catch (const std::bad_alloc &) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: mesh '%s': out of memory building its half-edge mesh",
                             name);
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: mesh '%s': OpenMesh failed: %s", name, e.what());
    } catch (...) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: mesh '%s': OpenMesh failed", name);
    }
}
