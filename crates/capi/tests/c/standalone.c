/* Standalone mode from plain C99: Tessera makes its own device, renders the embedded spot mesh
 * with every technique into RGBA8 buffers this program reads, checks them, and writes them
 * (raw RGBA, one file per technique) for the Rust test to compare with its own render of the
 * same view; then draws spot with a colour texture and a height map given as C arrays
 * (gregory, acc) and checks that each changes the image. Usage: standalone OUT_DIR. Exit 0 on
 * success; messages on stderr. */
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

/* Pixels of a and b (W x H RGBA8) differing by more than 24 in a channel. */
static size_t differing(const unsigned char *a, const unsigned char *b) {
    size_t i, c, n = 0;
    for (i = 0; i < (size_t)W * H; i++) {
        for (c = 0; c < 4; c++) {
            if (abs((int)a[4 * i + c] - (int)b[4 * i + c]) > 24) {
                n++;
                break;
            }
        }
    }
    return n;
}

/* Spot with gregory and acc: a red/blue checker texture and a height map (0.5..1) given as C
 * arrays must each change the image (texture: the colours; displace: the silhouette); a texture
 * on flat and PARAM_ERROR without the lattice are refused by name. 1 when all held. */
static int draw_maps(TesseraContext *ctx, const TesseraFrameDesc *base) {
    static unsigned char texels[16 * 16 * 4];
    static float heights[8 * 8];
    static const TesseraTechnique single_pass[] = {TESSERA_TECHNIQUE_GREGORY,
                                                   TESSERA_TECHNIQUE_ACC};
    size_t i, t;
    int ok = 1;
    unsigned char *plain = malloc((size_t)W * H * 4), *other = malloc((size_t)W * H * 4);
    if (plain == NULL || other == NULL) return 0;
    for (i = 0; i < 16 * 16; i++) {
        int red = ((i % 16) / 4 + (i / 16) / 4) % 2 == 0;
        texels[4 * i] = red ? 230 : 20;
        texels[4 * i + 1] = 20;
        texels[4 * i + 2] = red ? 20 : 230;
        texels[4 * i + 3] = 255;
    }
    for (i = 0; i < 8 * 8; i++) heights[i] = 0.5f + 0.5f * (float)(i % 8) / 7.0f;

    for (t = 0; t < 2; t++) {
        TesseraSurfaceDesc sdesc;
        TesseraSurface *bare = NULL, *mapped = NULL;
        TesseraFrameDesc frame = *base;
        size_t textured, displaced;

        check(tessera_surface_desc_default(&sdesc), TESSERA_STATUS_OK, "surface defaults");
        if (sdesc.texture != NULL || sdesc.height_map != NULL || sdesc.param_error != 0) {
            fprintf(stderr, "surface defaults hold maps\n");
            ok = 0;
        }
        sdesc.technique = single_pass[t];
        check(tessera_surface_create_obj(ctx, NULL, 0, NULL, &sdesc, &bare), TESSERA_STATUS_OK,
              "spot without maps");
        sdesc.texture = texels;
        sdesc.texture_width = 16;
        sdesc.texture_height = 16;
        sdesc.height_map = heights;
        sdesc.height_map_width = 8;
        sdesc.height_map_height = 8;
        check(tessera_surface_create_obj(ctx, NULL, 0, NULL, &sdesc, &mapped), TESSERA_STATUS_OK,
              "spot with maps");
        if (bare == NULL || mapped == NULL) {
            ok = 0;
            continue;
        }
        if (frame.no_reparam != 0 || frame.displace != 0.0f || frame.show != TESSERA_SHOW_SHADING) {
            fprintf(stderr, "frame defaults: no_reparam %u, displace %g, show %u\n", frame.no_reparam,
                    (double)frame.displace, frame.show);
            ok = 0;
        }
        check(tessera_render(ctx, bare, &frame, plain, (size_t)W * H * 4), TESSERA_STATUS_OK,
              "render without maps");
        check(tessera_render(ctx, mapped, &frame, other, (size_t)W * H * 4), TESSERA_STATUS_OK,
              "render with texture");
        textured = differing(plain, other);
        frame.displace = 0.3f;
        check(tessera_render(ctx, mapped, &frame, plain, (size_t)W * H * 4), TESSERA_STATUS_OK,
              "render displaced");
        displaced = differing(plain, other);
        if (textured < (size_t)W * H / 20 || displaced < (size_t)W * H / 50) {
            fprintf(stderr, "technique %u: texture changed %lu pixels, displace %lu\n",
                    single_pass[t], (unsigned long)textured, (unsigned long)displaced);
            ok = 0;
        }
        frame.displace = 0.0f;
        frame.show = TESSERA_SHOW_PARAM_ERROR;
        check(tessera_render(ctx, mapped, &frame, plain, (size_t)W * H * 4),
              TESSERA_STATUS_UNSUPPORTED, "PARAM_ERROR without the lattice");
        check(tessera_surface_destroy(ctx, bare), TESSERA_STATUS_OK, "destroy bare");
        check(tessera_surface_destroy(ctx, mapped), TESSERA_STATUS_OK, "destroy mapped");
    }
    {
        TesseraSurfaceDesc flat;
        TesseraSurface *s = NULL;
        check(tessera_surface_desc_default(&flat), TESSERA_STATUS_OK, "surface defaults");
        flat.technique = TESSERA_TECHNIQUE_FLAT;
        flat.texture = texels;
        flat.texture_width = 16;
        flat.texture_height = 16;
        check(tessera_surface_create_obj(ctx, NULL, 0, NULL, &flat, &s), TESSERA_STATUS_UNSUPPORTED,
              "texture on flat");
        if (s != NULL) ok = 0;
    }
    free(plain);
    free(other);
    return ok;
}

int main(int argc, char **argv) {
    static const char *names[] = {"flat", "phong", "pn", "bft", "adaptive", "gregory", "acc"};
    static const TesseraTechnique techniques[] = {
        TESSERA_TECHNIQUE_FLAT,     TESSERA_TECHNIQUE_PHONG,   TESSERA_TECHNIQUE_PN,
        TESSERA_TECHNIQUE_BFT,      TESSERA_TECHNIQUE_ADAPTIVE, TESSERA_TECHNIQUE_GREGORY,
        TESSERA_TECHNIQUE_ACC};
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
    memset(&cdesc, 0, sizeof cdesc);
    cdesc.validation = TESSERA_VALIDATION_SYNCHRONIZATION;
    cdesc.pipeline_cache = TESSERA_PIPELINE_CACHE_OFF;
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
    if (!draw_maps(ctx, &frame)) failures++;
    check(tessera_context_validation_errors(ctx, &errors), TESSERA_STATUS_OK, "validation count");
    if (errors != 0) {
        fprintf(stderr, "%u validation errors\n", errors);
        failures++;
    }
    check(tessera_context_destroy(ctx), TESSERA_STATUS_OK, "destroy context");
    check(tessera_context_destroy(ctx), TESSERA_STATUS_DESTROYED_HANDLE, "destroy context twice");
    free(pixels);
    if (failures == 0) printf("standalone C: 7 techniques rendered, texture and height map drawn\n");
    return failures == 0 ? 0 : 1;
}
