/* SPDX-License-Identifier: MIT */
/* Macro template: the shared per-point layers of a PointNet stage (PNB_FN): LIDET_PN_BLOCK points at a time are
 * loaded into the model frame, run through the layers in two ping-pong buffers, and the last layer's block
 * output is folded into a running maximum over the points (no N x C buffer).
 *
 * Instantiated by (each #include once, after #defining the parameters below; both name the function
 * run_points):
 *   lib/src/pointnet/lidet_pointnet.c    float: lidet_pn_layer_t, float points (m), the float dense kernel
 *                                       (lidet__nn_dense_f32) writing each layer's output itself
 *   lib/src/pointnet/lidet_pointnet_q.c  int8: lidet_pointnet_q_layer_t, int16_t points (mm), int32
 *                                       accumulators requantized to int8 between layers, a fused int8 kernel
 *                                       where the layer has packed weights
 *
 * Parameters:
 *   PNB_FN                      the name of the function defined here
 *   PNB_LAYER_T                 the layer descriptor (member n_out)
 *   PNB_BUFS_T                  the scratch view (member act[2]: the two ping-pong buffers)
 *   PNB_PTS_T                   the proposal's point coordinate type (3 per point)
 *   PNB_FRAME_T                 the frame argument (rotation, shift) the points are loaded into
 *   PNB_MAX_INIT(b, n)          reset the running maximum of n channels
 *   PNB_LOAD(b, pts, nb, f)     load nb points into the model frame; yields the block (const void *)
 *   PNB_DENSE(ly, in, nb, b, l) layer l on the block `in` (the loaded points when l == 0)
 *   PNB_STORE(ly, nb, b, dst)   write a hidden layer's output to dst, the next layer's input
 *   PNB_FOLD_MAX(ly, nb, b, l)  fold the last layer's output into the running maximum
 *   PNB_FUSED(ly, in, nb, b, l, dst)  the whole layer in one pass (DENSE and STORE to dst, or DENSE and FOLD_MAX
 *                               when dst is NULL): nonzero when it did, 0 to take DENSE and STORE / FOLD_MAX
 *                               (the float build: always 0)
 * The float kernel writes its output in PNB_DENSE (STORE does nothing); the int8 one accumulates in int32
 * (DENSE), requantizes hidden layers (STORE) and takes the maximum on the accumulators (FOLD_MAX).
 * Defines: static void PNB_FN(const PNB_LAYER_T *layers, uint32_t n_layers, const PNB_BUFS_T *b,
 * const PNB_PTS_T *pts, uint32_t n, const PNB_FRAME_T *f).
 *
 * Why a template: the two builds' layers, buffers and points are different types and their layer steps are
 * different kernels (one float call; an int8 accumulate, requantize and max, or one fused call), which a C99
 * function could only take through void pointers and function pointers. The loop's cost is in the kernels, so
 * speed does not decide here: the template keeps one block and ping-pong schedule (the same blocks, the same
 * buffer for each layer) for both, with each build's calls checked by the compiler.
 * Not a public header; include nowhere else. */

static void PNB_FN(const PNB_LAYER_T *layers, uint32_t n_layers, const PNB_BUFS_T *b, const PNB_PTS_T *pts,
                   uint32_t n, const PNB_FRAME_T *f)
{
    uint32_t p0, l;
    PNB_MAX_INIT(b, layers[n_layers - 1u].n_out);
    for (p0 = 0; p0 < n; p0 += LIDET_PN_BLOCK)
    {
        const uint32_t nb = n - p0 < LIDET_PN_BLOCK ? n - p0 : LIDET_PN_BLOCK;
        const void *cur = PNB_LOAD(b, pts + 3u * p0, nb, f);
        for (l = 0; l < n_layers; ++l)
        {
            const PNB_LAYER_T *ly = &layers[l];
            const int last = l + 1u == n_layers;
            if (!PNB_FUSED(ly, cur, nb, b, l, last ? 0 : b->act[l & 1u]))
            {
                PNB_DENSE(ly, cur, nb, b, l);
                if (last)
                {
                    PNB_FOLD_MAX(ly, nb, b, l);
                }
                else
                {
                    PNB_STORE(ly, nb, b, b->act[l & 1u]);
                }
            }
            if (!last)
            {
                cur = b->act[l & 1u];
            }
        }
    }
}
