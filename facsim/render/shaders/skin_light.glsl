// Skin's light beyond the rig's common terms: how far light scatters under it (by the surface's
// curvature) and its specular lobes by region. Included by face.frag.glsl before main(); skin
// variants only.
#ifdef REGION_SKIN
// Pre-integrated skin (Penner 2011): light travels a few millimetres under the skin, so where the
// surface curves tightly within that distance (the nose, the lips, the lids, the ears) the
// shading wraps past the terminator, warm; where it is broad (the forehead, the cheeks) the
// falloff is nearly a hard surface's. One wrap everywhere softened the broad planes' modelling
// too: an even, waxy face. ``curvature``: 1 / radius in dm^-1 (a nose tip ~15, a cheek ~2; its sign, hollow or bulge, does not matter here);
// returns the share of the full wrap (SCATTER_WRAP) the surface gets.
const float SCATTER_CURVATURE = 12.0;   // dm^-1 (a radius of ~8 mm) at which the wrap is full
const float BROAD_WRAP = 0.35;          // the share left on broad, flat skin
float scatter_reach(float curvature) {
    return clamp(BROAD_WRAP + (1.0 - BROAD_WRAP) * abs(curvature) / SCATTER_CURVATURE, BROAD_WRAP, 1.2);
}

// The skin's two specular lobes (broad, tight) by region: the T-zone (``oil``: oil_density in
// facsim.head.appearance, the forehead's middle, the nose, the chin) is smoother and shinier
// than the drier cheeks, its sheen uneven in patches a centimetre or so across (``patches``)
// and broken at the millimetre scale (``blotch``), never one even glaze; the oil film's tighter
// lobe only where the skin is oiliest (``film``); the lips (``lips``: their mask) and their wet
// film (``wet``: the lips' film and the mucosa) their own. (Until
// session 18 one broad lobe of weight 0.6 and roughness 0.6 lay over the whole face.)
struct SkinLobes { vec2 weight; vec2 roughness; float lip; };   // lip: how far the lips' lobes hold
// Sebum pools on an oily T-zone: the film gathers in the skin's relief in pools a few
// millimetres across (cells ~6 and ~2.5 mm on hm08's face UV) with drier skin between them, so
// its highlight is broken and sharper, not one broad even glaze (kwame's "plastic" forehead,
// session 22's blind review). Returns the film's thickness multiplier, 0 (dry) to OIL_POOL_PEAK,
// a little over 1 on average: the tighter lobe keeps the T-zone shinier than the cheeks.
const vec2 OIL_POOL_CELLS = vec2(60.0, 120.0);
const float OIL_POOL_PEAK = 1.8;
float oil_pools(vec2 skin_uv) {
    float n = 0.65 * value_noise(skin_uv * OIL_POOL_CELLS + 53.0, 0)
            + 0.35 * value_noise(GRAIN_TURN * skin_uv * (2.4 * OIL_POOL_CELLS) + 71.0, 0);
    return OIL_POOL_PEAK * smoothstep(0.30, 0.60, n);
}
// (Until session 24 0.6 and 0.26 (0.62 and 0.22 until session 23): kwame's forehead at 448 px
// carried a white patch, its brightest specular light 0.99 of the forehead's median light, the
// blind reviewer's "shiny plastic forehead" on 15 of his 26 images; now 0.66 (tests/test_skin.py).
// A face photographed as a stimulus shows a soft lift of its T-zone, not a glaze. The T-zone's
// broad lobe weighs as the cheeks' but is narrower (TZONE_BROAD_ROUGHNESS; the cheeks' 0.66): its
// peak still brighter.)
const float BROAD_LOBE_WEIGHT = 0.42;   // the horny layer's broad lobe, cheeks and T-zone alike
const float TZONE_BROAD_ROUGHNESS = 0.54;
const float OIL_FILM_WEIGHT = 0.14;     // the film's tight lobe where it lies, times oil_pools
const float OIL_FILM_ROUGHNESS = 0.33;  // (0.42 until session 23: one broad, even highlight; 0.36 until
                                        // session 25, before the sheen saw the relief sharp: SHEEN_RELIEF)
SkinLobes skin_lobes(float oil, float film, float lips, float wet, float blotch, float patches) {
    float tzone = smoothstep(0.4, 0.85, oil);
    float lip = max(lips, min(2.0 * wet, 1.0));   // the lips' lobes (LIP_LOBES in face.frag.glsl)
    float uneven = (0.7 + 0.6 * patches) * (0.8 + 0.4 * blotch);
    SkinLobes l;
    l.weight = vec2(mix(BROAD_LOBE_WEIGHT * uneven, LIP_LOBES.x, lip),
                    (0.08 * tzone + OIL_FILM_WEIGHT * film) * uneven + LIP_LOBES.y * wet);
    l.lip = lip;
    l.roughness = vec2(mix(mix(0.66, TZONE_BROAD_ROUGHNESS, tzone), LIP_BROAD_ROUGHNESS, lip), mix(mix(0.48, OIL_FILM_ROUGHNESS, min(film, 1.0)), LIP_ROUGHNESS, lip));
    return l;
}
#endif
