// The white furnace, three.js (MeshStandardMaterial, its own PMREM of a uniform environment of radiance 1): one
// camera-facing 1-pixel quad per (NoV, row); each quad's vertex normals are all (0, sin t, cos t), so NoV = cos t is
// the same at every fragment, the normal's screen derivatives (three.js's geometryRoughness) are zero and roughness is
// the material's. Orthographic camera, float render target, no tone mapping, linear output.
import * as THREE from 'three';
import { expose } from '/web/furnace.js';
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

// rows: [{ roughness, metalness, color: [r, g, b] }], nov: [NoV per column]. Returns the RGBA float pixels, row 0 at
// the bottom (row i of the result is rows[i]).
async function furnace( { nov, rows } ) {

	const width = nov.length, height = rows.length;
	const renderer = new THREE.WebGLRenderer( { antialias: false } );
	renderer.setSize( width, height, false );
	renderer.toneMapping = THREE.NoToneMapping;
	renderer.outputColorSpace = THREE.LinearSRGBColorSpace;

	const ones = new Float32Array( 8 * 4 * 4 ).fill( 1 );
	const env = new THREE.DataTexture( ones, 8, 4, THREE.RGBAFormat, THREE.FloatType );
	env.mapping = THREE.EquirectangularReflectionMapping;
	env.colorSpace = THREE.LinearSRGBColorSpace;
	env.needsUpdate = true;

	const scene = new THREE.Scene();
	scene.environment = env;
	const camera = new THREE.OrthographicCamera( 0, width, height, 0, - 1, 1 );

	rows.forEach( ( row, y ) => {

		const position = [], normal = [], index = [];
		nov.forEach( ( c, x ) => {

			const s = Math.sqrt( Math.max( 0, 1 - c * c ) );
			const base = position.length / 3;
			position.push( x, y, 0, x + 1, y, 0, x + 1, y + 1, 0, x, y + 1, 0 );
			for ( let k = 0; k < 4; k ++ ) normal.push( 0, s, c );
			index.push( base, base + 1, base + 2, base, base + 2, base + 3 );

		} );
		const geometry = new THREE.BufferGeometry();
		geometry.setAttribute( 'position', new THREE.Float32BufferAttribute( position, 3 ) );
		geometry.setAttribute( 'normal', new THREE.Float32BufferAttribute( normal, 3 ) );
		geometry.setIndex( index );
		const material = new THREE.MeshStandardMaterial( {
			color: new THREE.Color().setRGB( ...row.color, THREE.LinearSRGBColorSpace ),
			roughness: row.roughness,
			metalness: row.metalness,
		} );
		scene.add( new THREE.Mesh( geometry, material ) );

	} );

	const target = new THREE.WebGLRenderTarget( width, height, {
		type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false,
		minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
	} );
	renderer.setRenderTarget( target );
	renderer.render( scene, camera );
	const pixels = new Float32Array( width * height * 4 );
	renderer.readRenderTargetPixels( target, 0, 0, width, height, pixels );
	renderer.setRenderTarget( null );
	renderer.render( scene, camera );
	return { width, height, pixels, canvas: renderer.domElement, renderer: renderer.getContext().getParameter( renderer.getContext().RENDERER ) };

}

expose( furnace, ( spec ) => loadWrong( spec.mistake || 'none' ) );
