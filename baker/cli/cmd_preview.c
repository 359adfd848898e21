/*
 * `lmbake preview OUT.gltf [--port N] [--lightmap ktx2|hdr]`: serves a baked level to a browser on 127.0.0.1 (the
 * three.js page of tools/preview; docs/preview.md). `lmbake preview --watch LEVEL [-c CONFIG]
 * [-o OUTDIR]` bakes the level and bakes it again on every save, the page following
 * (docs/watch.md). The server and the watch are node's: this command checks its arguments and
 * hands over to tools/preview/serve.mjs or watch.mjs (which runs this lmbake for the bakes).
 */
#define _POSIX_C_SOURCE 200809L
#include "cli_common.h"
#include "commands.h"
#include "node_tool.h"

#include <limits.h>
#include <string.h>
#include <unistd.h>

static const char help[] =
    "usage: lmbake preview OUT.gltf [--port N] [--lightmap ktx2|hdr]\n"
    "       lmbake preview --watch LEVEL.gltf|glb [-c CONFIG] [-o OUTDIR] [--no-quick] [--port N]\n"
    "                      [--lightmap ktx2|hdr]\n"
    "\n"
    "Serves a baked level (the .gltf `lmbake bake` wrote) on http://127.0.0.1:PORT/ and prints\n"
    "the address; open it in a browser. Views: lit, lightmap only, UV1 checker with texel grid,\n"
    "invalid texels, each atlas flat with a texel readout. Nothing is loaded from the internet\n"
    "and only this machine can connect. Ctrl-C stops it.\n"
    "\n"
    "With --watch: bakes LEVEL (as 'lmbake bake LEVEL -c CONFIG -o OUTDIR'), serves the preview and\n"
    "watches the level, its buffers and images, the config and its sky image. On every save it\n"
    "bakes again: a quick look first (bake --quick, kept out of OUTDIR), then the real bake into\n"
    "OUTDIR; the open page shows each from the same camera. A save during a bake stops it and\n"
    "bakes the newest; a save that does not bake keeps the last good bake on screen with the\n"
    "error. GET /status gives the state as JSON (docs/watch.md).\n"
    "\n"
    "  --watch      bake LEVEL and follow its changes (see above)\n"
    "  -c, --config FILE, -o, --output DIR\n"
    "               with --watch: the bake's config and output folder (default ./lmbake-out)\n"
    "  --no-quick   with --watch: no quick look, only the real bakes\n"
    "  --port N     port to listen on (default: a free one)\n"
    "  --lightmap ktx2|hdr\n"
    "               which file of each atlas the page reads: its KTX2 when the glTF names one\n"
    "               (the default), or the Radiance .hdr\n"
    "  -h, --help   this help\n";

int cmd_preview(int argc, char **argv)
{
    const char *gltf = NULL, *port = NULL, *source = NULL, *config = NULL, *outdir = NULL, *v;
    int watch = 0, no_quick = 0;
    for (int i = 1; i < argc; i++) {
        int r;
        unsigned long long n;
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(help, stdout);
            return LMB_OK;
        } else if ((r = cli_opt_value(argc, argv, &i, "--port", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 65535, &n))
                return cli_usage_error("preview", "--port needs a number 0..65535");
            port = v;
        } else if (cli_is_flag(argv[i], "--watch", NULL)) {
            watch = 1;
        } else if (cli_is_flag(argv[i], "--no-quick", NULL)) {
            no_quick = 1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--config", "-c", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("preview", "%s needs a file", argv[i]);
            config = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--output", "-o", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("preview", "%s needs a folder", argv[i]);
            outdir = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--lightmap", NULL, &v)) != 0) {
            if (r < 0 || (strcmp(v, "ktx2") != 0 && strcmp(v, "hdr") != 0))
                return cli_usage_error("preview", "--lightmap needs ktx2 or hdr");
            source = v;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("preview", "unknown option '%s'", argv[i]);
        } else if (gltf) {
            return cli_usage_error("preview", "one glTF at a time ('%s' and '%s')", gltf, argv[i]);
        } else {
            gltf = argv[i];
        }
    }
    if (!gltf)
        return cli_usage_error("preview", watch ? "no LEVEL given (the .gltf or .glb to bake and watch)"
                                                : "no OUT.gltf given (the .gltf that `lmbake bake` wrote)");
    if (!watch && (config || outdir || no_quick))
        return cli_usage_error("preview", "-c, -o and --no-quick go with --watch (which bakes); a baked .gltf is shown "
                                          "as it is");
    if (access(gltf, R_OK) != 0) {
        lmb_error err;
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot open '%s' for the preview", gltf);
        return cli_fail(&err);
    }
    if (config && access(config, R_OK) != 0) {
        lmb_error err;
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot open config '%s'", config);
        return cli_fail(&err);
    }
    char script[PATH_MAX + 64], self[PATH_MAX];
    if (!node_tool_path(watch ? "watch.mjs" : "serve.mjs", script, sizeof script))
        return LMB_ERR_INTERNAL;
    char *args[14] = {(char *)gltf};
    int n = 1;
    if (watch) { /* the bakes run this very lmbake */
        ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
        if (len <= 0)
            return cli_fail(&(lmb_error){LMB_ERR_INTERNAL, "cannot find the lmbake executable (/proc/self/exe)"});
        self[len] = '\0';
        args[n++] = "--lmbake";
        args[n++] = self;
    }
    if (no_quick)
        args[n++] = "--no-quick";
    if (config) {
        args[n++] = "-c";
        args[n++] = (char *)config;
    }
    if (outdir) {
        args[n++] = "-o";
        args[n++] = (char *)outdir;
    }
    if (port) {
        args[n++] = "--port";
        args[n++] = (char *)port;
    }
    if (source) {
        args[n++] = "--lightmap";
        args[n++] = (char *)source;
    }
    return node_tool_exec(script, args);
}
