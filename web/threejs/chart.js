// The chart both three.js pages render (furnace.js, rectarea.js): one camera-facing 1-pixel quad per (NoV, row) of
// MeshStandardMaterial; each quad's vertex normals are all (0, sin t, cos t), so under the orthographic camera (three.js's
// view direction is then (0, 0, 1)) NoV = cos t is the same at every fragment, the normal's screen derivatives
// (three.js's geometryRoughness) are zero and roughness is the material's. A quad spans `scale` world units. Float
// render target, no tone mapping, linear output.
import * as THREE from 'three';

// rows: [{ roughness, metalness, color: [r, g, b] }], nov: [NoV per column]: the scene (quad (x, y) at
// [x, x + 1] x [y, y + 1] times scale, z = 0) and its camera
export function chartScene( { nov, rows }, scale = 1 ) {

	const width = nov.length, height = rows.length;
	const scene = new THREE.Scene();
	const camera = new THREE.OrthographicCamera( 0, width * scale, height * scale, 0, - 10, 10 );

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
		geometry.setAttribute( 'position', new THREE.Float32BufferAttribute( position.map( ( p ) => p * scale ), 3 ) );
		geometry.setAttribute( 'normal', new THREE.Float32BufferAttribute( normal, 3 ) );
		geometry.setIndex( index );
		const material = new THREE.MeshStandardMaterial( {
			color: new THREE.Color().setRGB( ...row.color, THREE.LinearSRGBColorSpace ),
			roughness: row.roughness,
			metalness: row.metalness,
		} );
		scene.add( new THREE.Mesh( geometry, material ) );

	} );
	return { scene, camera, width, height };

}

// One WebGLRenderer for every render of the page (as Babylon's pages keep one Engine): three.js compiles a material's
// program once per renderer, so a page's later renders (the tests' variants) reuse the first one's programs; what
// differs between them (the tables' texels, flipY, the textures bound) three.js uploads on needsUpdate / binds per
// render as it would in a fresh renderer
let renderer = null;

// Renders into a float target and reads it back: { width, height, pixels (RGBA, row 0 at the bottom), canvas, renderer
// (the GL renderer's name), webgl (three.js's WebGLRenderer) }; the canvas shows the same render.
export function renderFloat( { scene, camera, width, height } ) {

	renderer ??= new THREE.WebGLRenderer( { antialias: false } );
	renderer.setSize( width, height, false );
	renderer.toneMapping = THREE.NoToneMapping;
	renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
	const target = new THREE.WebGLRenderTarget( width, height, {
		type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false,
		minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
	} );
	renderer.setRenderTarget( target );
	renderer.render( scene, camera );
	const pixels = new Float32Array( width * height * 4 );
	renderer.readRenderTargetPixels( target, 0, 0, width, height, pixels );
	renderer.setRenderTarget( null );
	target.dispose();
	renderer.render( scene, camera );
	const gl = renderer.getContext();
	return { width, height, pixels, canvas: renderer.domElement, renderer: gl.getParameter( gl.RENDERER ), webgl: renderer };

}
