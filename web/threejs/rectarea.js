// One RectAreaLight (radiance 1, one-sided) over the chart of chart.js (one 1-pixel MeshStandardMaterial quad per
// (NoV, row), `scale` world units each), nothing else in the scene: each pixel is three.js's LTC area-light specular
// (RE_Direct_RectArea_Physical) at its own shading point, normal, roughness and light polygon.
//
// The tables: RectAreaLightUniformsLib.init() builds three.js's four DataTextures (LTC_FLOAT_1/2, LTC_HALF_1/2: 64²
// RGBA, linear, clamp, flipY false) into UniformsLib, which WebGLLights hands to the shader (the FLOAT pair where
// OES_texture_float_linear exists, else the HALF pair). ?lut=lutbake (spec.lut) writes lutbake's LTC_MAT_1 / LTC_MAT_2
// (ltc_threejs.js) into those same textures, as init() writes its own arrays (half: DataUtils.toHalfFloat).
import * as THREE from 'three';
import { RectAreaLightUniformsLib } from '/web/node_modules/three/examples/jsm/lights/RectAreaLightUniformsLib.js';
import { RectAreaLightTexturesLib } from '/web/node_modules/three/examples/jsm/lights/RectAreaLightTexturesLib.js';
import { expose } from '/web/furnace.js';
import { chartScene, renderFloat } from '/web/threejs/chart.js';

RectAreaLightUniformsLib.init();
const NAMES = [ 'LTC_FLOAT_1', 'LTC_FLOAT_2', 'LTC_HALF_1', 'LTC_HALF_2' ];
const shipped = Object.fromEntries( NAMES.map( ( n ) => [ n, RectAreaLightTexturesLib[ n ].image.data.slice() ] ) );
const params = new URLSearchParams( location.search );
// the light the demo shows (the tests pass their own): above the chart's top edge, facing its centre
const LIGHT = { position: [ 0.5, 1.1, 0.9 ], target: [ 0.5, 0.5, 0 ], width: 1.0, height: 0.6, intensity: 1 };
const SCALE = 1 / 32;

// lut 'shipped' | 'lutbake'; mistake 'none', 'swap' (LTC_1 and LTC_2 exchanged in UniformsLib) or 'flipY'
async function useTables( { lut = params.get( 'lut' ) || 'shipped', mistake = 'none' } ) {

	let mats = [ shipped.LTC_FLOAT_1, shipped.LTC_FLOAT_2 ];
	if ( lut === 'lutbake' ) {

		const module = await import( '/lut/ltc_threejs.js' );
		mats = [ module.LTC_MAT_1, module.LTC_MAT_2 ];

	}
	NAMES.forEach( ( name, k ) => {

		const texture = RectAreaLightTexturesLib[ name ];
		const values = mats[ k % 2 ];
		const data = texture.image.data;
		for ( let i = 0; i < data.length; i ++ ) data[ i ] = name.includes( 'HALF' ) ? THREE.DataUtils.toHalfFloat( values[ i ] ) : values[ i ];
		texture.flipY = mistake === 'flipY';
		texture.needsUpdate = true;

	} );
	const [ one, two ] = mistake === 'swap' ? [ 2, 1 ] : [ 1, 2 ];
	for ( const kind of [ 'FLOAT', 'HALF' ] ) {

		THREE.UniformsLib[ `LTC_${ kind }_1` ] = RectAreaLightTexturesLib[ `LTC_${ kind }_${ one }` ];
		THREE.UniformsLib[ `LTC_${ kind }_2` ] = RectAreaLightTexturesLib[ `LTC_${ kind }_${ two }` ];

	}

}

// spec: { nov, rows } (chart.js), light: { position, target, width, height, intensity } in world units, scale
async function rectArea( { light = LIGHT, scale = SCALE, ...spec } ) {

	const chart = chartScene( spec, scale );
	const rect = new THREE.RectAreaLight( 0xffffff, light.intensity, light.width, light.height );
	rect.position.set( ...light.position );
	rect.lookAt( ...light.target );
	chart.scene.add( rect );
	const result = renderFloat( chart );
	result.info = { floatLinear: result.webgl.extensions.has( 'OES_texture_float_linear' ) };
	return result;

}

expose( rectArea, useTables );
