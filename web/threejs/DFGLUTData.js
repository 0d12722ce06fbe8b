// three.js's own src/renderers/shaders/DFGLUTData.js (r187), its getDFGLUT() line for line, reading the table from
// lutbake's DFGLUTData.js (a Uint16Array of half floats, 16 x 16 RG) instead of the array compiled into three.js.
// furnace.html's import map points three's module URL here. globalThis.lutbakeMistake, set by the test driver only,
// loads the same file wrong on purpose (tests/test_web_threejs.py must see each mistake); the table is made again when
// it changes.
import { DataTexture, RGFormat, HalfFloatType, LinearFilter, ClampToEdgeWrapping } from 'three';
import LUTBAKE from 'lutbake/DFGLUTData.js';

function mistaken( data, mistake ) {

	const out = new Uint16Array( data.length );
	for ( let y = 0; y < 16; y ++ ) for ( let x = 0; x < 16; x ++ ) for ( let c = 0; c < 2; c ++ ) {

		const src = ( y * 16 + x ) * 2 + c;
		if ( mistake === 'swapRG' ) out[ src ] = data[ ( y * 16 + x ) * 2 + ( 1 - c ) ];
		else if ( mistake === 'transpose' ) out[ src ] = data[ ( x * 16 + y ) * 2 + c ];
		else out[ src ] = data[ src ];

	}
	return out;

}

let lut = null;
let lutMistake = 'none';

export function getDFGLUT() {

	const mistake = globalThis.lutbakeMistake || 'none';
	if ( lut === null || mistake !== lutMistake ) {

		lutMistake = mistake;
		lut = new DataTexture( mistaken( LUTBAKE, mistake ), 16, 16, RGFormat, HalfFloatType );
		lut.name = 'DFG_LUT';
		lut.minFilter = LinearFilter;
		lut.magFilter = LinearFilter;
		lut.wrapS = ClampToEdgeWrapping;
		lut.wrapT = ClampToEdgeWrapping;
		lut.generateMipmaps = false;
		lut.flipY = mistake === 'flipY';
		lut.needsUpdate = true;

	}

	return lut;

}
