/*
 * Where a glTF URI may point (baker/load/uri.c, issue 15): relative paths inside the input's
 * folder are normalised ("a/./b/../c.png" -> "a/c.png", %-escapes decoded); schemes, absolute
 * paths, ".." that leaves the folder (also %-escaped) and malformed escapes are refused.
 */
#include "check.h"

#include "load/uri.h"

static void expect(const char *uri, lmb_uri_kind kind, const char *relative)
{
    char rel[256] = "";
    lmb_uri_kind k = lmb_uri_check(uri, rel, sizeof rel);
    if (k != kind || (relative && strcmp(rel, relative) != 0)) {
        fprintf(stderr, "uri '%s': kind %d, relative '%s'; expected kind %d, '%s'\n", uri, (int)k, rel, (int)kind,
                relative ? relative : "");
        check_failed_count++;
    }
}

int main(void)
{
    expect("tex.png", LMB_URI_INSIDE, "tex.png");
    expect("textures/./wall.png", LMB_URI_INSIDE, "textures/wall.png");
    expect("a/b/../c.png", LMB_URI_INSIDE, "a/c.png");
    expect("a/../b.png", LMB_URI_INSIDE, "b.png");
    expect("my%20texture.png", LMB_URI_INSIDE, "my texture.png");
    expect("$(touch a/b).png", LMB_URI_INSIDE, "$(touch a/b).png"); /* a name; whether it exists is the filesystem's call */
    expect("data:image/png;base64,AAAA", LMB_URI_EMBEDDED, NULL);
    expect("../outside.png", LMB_URI_ESCAPES, NULL);
    expect("a/../../outside.png", LMB_URI_ESCAPES, NULL);
    expect("%2e%2e/outside.png", LMB_URI_ESCAPES, NULL);
    expect("a/%2E%2E/%2e%2e/x", LMB_URI_ESCAPES, NULL);
    expect("/etc/passwd", LMB_URI_ABSOLUTE, NULL);
    expect("%2fetc/passwd", LMB_URI_ABSOLUTE, NULL);
    expect("file:///etc/passwd", LMB_URI_SCHEME, NULL);
    expect("http://example.com/a.png", LMB_URI_SCHEME, NULL);
    expect("C:/textures/a.png", LMB_URI_SCHEME, NULL); /* "C:" reads as a scheme: refused either way */
    expect("a\\b.png", LMB_URI_MALFORMED, NULL);
    expect("bad%zzescape.png", LMB_URI_MALFORMED, NULL);
    expect("nul%00.png", LMB_URI_MALFORMED, NULL);
    expect("trailing%2", LMB_URI_MALFORMED, NULL);
    expect("", LMB_URI_MALFORMED, NULL);
    expect("./", LMB_URI_MALFORMED, NULL);
    return check_failures();
}
