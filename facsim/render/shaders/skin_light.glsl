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
struct SkinLobes { vec2 weight; vec2 roughness; };
SkinLobes skin_lobes(float oil, float film, float lips, float wet, float blotch, float patches) {
    float tzone = smoothstep(0.4, 0.85, oil);
    float lip = max(lips, min(2.0 * wet, 1.0));   // the lips' lobes (LIP_LOBES in face.frag.glsl)
    float uneven = (0.7 + 0.6 * patches) * (0.8 + 0.4 * blotch);
    SkinLobes l;
    l.weight = vec2(mix(mix(0.42, 0.62, tzone) * uneven, LIP_LOBES.x, lip),
                    (0.08 * tzone + 0.22 * film) * uneven + LIP_LOBES.y * wet);
    l.roughness = vec2(mix(mix(0.66, 0.54, tzone), LIP_BROAD_ROUGHNESS, lip), mix(mix(0.48, 0.42, film), LIP_ROUGHNESS, lip));
    return l;
}
#endif
