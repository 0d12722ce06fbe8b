// The white furnace, three.js (MeshStandardMaterial, its own PMREM of a uniform environment of radiance 1) on the chart
// of chart.js: one 1-pixel quad per (NoV, row).
import * as THREE from 'three';
import { expose } from '/web/furnace.js';
import { chartScene, renderFloat } from '/web/threejs/chart.js';
// three.js's own DFG module: furnace.html's import map points this URL at lutbake's DFGLUTData.js (?lut=lutbake), which
// replaces three's file as it is; three's shaders and this page get the one texture getDFGLUT() makes
import { getDFGLUT } from '/web/node_modules/three/src/renderers/shaders/DFGLUTData.js';

// The table loaded wrong on purpose (the test driver only: tests/test_web_threejs.py must see each mistake): the
// texture getDFGLUT() returns, its texels or its upload changed in place from a pristine copy.
function loadWrong( mistake ) {

	const lut = getDFGLUT();
	const { width, height, data } = lut.image;
	lut.userData.pristine ??= data.slice();
	const src = lut.userData.pristine;
	for ( let y = 0; y < height; y ++ ) for ( let x = 0; x < width; x ++ ) for ( let c = 0; c < 2; c ++ ) {

		const at = ( y * width + x ) * 2;
		if ( mistake === 'swapRG' ) data[ at + c ] = src[ at + 1 - c ];
		else if ( mistake === 'transpose' ) data[ at + c ] = src[ ( x * width + y ) * 2 + c ];
		else data[ at + c ] = src[ at + c ];

	}
	lut.flipY = mistake === 'flipY';
	lut.needsUpdate = true;

}

// The uniform environment, one texture for the page: three.js's renderer keeps its PMREM per texture, so the page's
// renders (chart.js: one renderer) prefilter it once (~4 s in SwiftShader) and the tests' variants, which change only
// the DFG table, reuse it
let env = null;

function uniformEnvironment() {

	if ( env ) return env;
	const ones = new Float32Array( 8 * 4 * 4 ).fill( 1 );
	env = new THREE.DataTexture( ones, 8, 4, THREE.RGBAFormat, THREE.FloatType );
	env.mapping = THREE.EquirectangularReflectionMapping;
	env.colorSpace = THREE.LinearSRGBColorSpace;
	env.needsUpdate = true;
	return env;

}

// spec: { nov, rows } (chart.js). Returns the RGBA float pixels, row 0 at the bottom (row i of the result is rows[i]).
async function furnace( spec ) {

	const chart = chartScene( spec );
	chart.scene.environment = uniformEnvironment();
	return renderFloat( chart );

}

expose( furnace, ( spec ) => loadWrong( spec.mistake || 'none' ) );
