/* Standalone mode from plain C99: Tessera makes its own device, renders the embedded spot mesh
 * with every technique into RGBA8 buffers this program reads, checks them, and writes them
 * (raw RGBA, one file per technique) for the Rust test to compare with its own render of the
 * same view. Usage: standalone OUT_DIR. Exit 0 on success; messages on stderr. */
#include "tessera.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 160
#define H 120

static int failures = 0;

static void check(TesseraStatus got, TesseraStatus want, const char *what) {
    if (got != want) {
        char message[512];
        tessera_last_error(NULL, message, sizeof message);
        fprintf(stderr, "%s: got %s, want %s (%s)\n", what, tessera_status_name((uint32_t)got),
                tessera_status_name((uint32_t)want), message);
        failures++;
    }
}

int main(int argc, char **argv) {
    static const char *names[] = {"flat", "phong", "pn", "bft", "adaptive"};
    static const TesseraTechnique techniques[] = {TESSERA_TECHNIQUE_FLAT, TESSERA_TECHNIQUE_PHONG,
                                                  TESSERA_TECHNIQUE_PN, TESSERA_TECHNIQUE_BFT,
                                                  TESSERA_TECHNIQUE_ADAPTIVE};
    TesseraStandaloneDesc cdesc;
    TesseraContext *ctx = NULL;
    TesseraFrameDesc frame;
    unsigned char *pixels;
    uint32_t errors = 1;
    size_t t;

    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
        return 2;
    }
    cdesc.device = NULL;
    cdesc.validation = TESSERA_VALIDATION_SYNCHRONIZATION;
    check(tessera_context_create_standalone(&cdesc, &ctx), TESSERA_STATUS_OK, "create context");
    if (ctx == NULL) return 1;

    check(tessera_frame_desc_default(&frame), TESSERA_STATUS_OK, "frame defaults");
    frame.width = W;
    frame.height = H;
    frame.factor = 4.0f;
    pixels = malloc((size_t)W * H * 4);
    if (pixels == NULL) return 1;

    for (t = 0; t < sizeof techniques / sizeof techniques[0]; t++) {
        TesseraSurfaceDesc sdesc;
        TesseraSurface *surface = NULL;
        size_t i, lit = 0;
        char path[1024];
        FILE *f;

        check(tessera_surface_desc_default(&sdesc), TESSERA_STATUS_OK, "surface defaults");
        sdesc.technique = techniques[t];
        check(tessera_surface_create_obj(ctx, NULL, 0, NULL, &sdesc, &surface), TESSERA_STATUS_OK,
              names[t]);
        if (surface == NULL) continue;
        memset(pixels, 0, (size_t)W * H * 4);
        check(tessera_render(ctx, surface, &frame, pixels, (size_t)W * H * 4), TESSERA_STATUS_OK,
              "render");
        /* A pixel is lit when it differs from the clear colour by more than rounding. */
        for (i = 0; i < (size_t)W * H; i++) {
            int r = pixels[4 * i], g = pixels[4 * i + 1], b = pixels[4 * i + 2];
            int cr = (int)(frame.clear_color[0] * 255.0f + 0.5f);
            int cg = (int)(frame.clear_color[1] * 255.0f + 0.5f);
            int cb = (int)(frame.clear_color[2] * 255.0f + 0.5f);
            if (abs(r - cr) > 2 || abs(g - cg) > 2 || abs(b - cb) > 2) lit++;
        }
        if (lit < (size_t)W * H / 20) {
            fprintf(stderr, "%s: only %lu of %d pixels show the surface\n", names[t],
                    (unsigned long)lit, W * H);
            failures++;
        }
        snprintf(path, sizeof path, "%s/%s.rgba", argv[1], names[t]);
        f = fopen(path, "wb");
        if (f == NULL || fwrite(pixels, 1, (size_t)W * H * 4, f) != (size_t)W * H * 4) {
            fprintf(stderr, "cannot write %s\n", path);
            failures++;
        }
        if (f != NULL) fclose(f);
        /* A wrong buffer size is refused before anything is drawn. */
        check(tessera_render(ctx, surface, &frame, pixels, (size_t)W * H * 4 - 1),
              TESSERA_STATUS_WRONG_SIZE, "short pixel buffer");
        check(tessera_surface_destroy(ctx, surface), TESSERA_STATUS_OK, "destroy surface");
        check(tessera_surface_destroy(ctx, surface), TESSERA_STATUS_DESTROYED_HANDLE,
              "destroy surface twice");
    }
    check(tessera_context_validation_errors(ctx, &errors), TESSERA_STATUS_OK, "validation count");
    if (errors != 0) {
        fprintf(stderr, "%u validation errors\n", errors);
        failures++;
    }
    check(tessera_context_destroy(ctx), TESSERA_STATUS_OK, "destroy context");
    check(tessera_context_destroy(ctx), TESSERA_STATUS_DESTROYED_HANDLE, "destroy context twice");
    free(pixels);
    if (failures == 0) printf("standalone C: 5 techniques rendered\n");
    return failures == 0 ? 0 : 1;
}
