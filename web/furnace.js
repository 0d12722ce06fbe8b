// What every engine's white-furnace page shares: the demo chart and the window API the tests (tests/web_harness.py)
// and web/index.html drive. An engine page calls expose( furnace, prepare ), where furnace( spec ) renders
// spec = { nov: [NoV per column], rows: [{ roughness, metalness, color }], ... } and resolves to
// { width, height, pixels (RGBA float, row 0 at the bottom), canvas, renderer, info?, dispose? }, and prepare( spec ) runs
// before each driven render (the wrong loads).

// NoV along x, roughness up; a metal of base colour (1, 0.5, 0.2) below, a black dielectric (f0 = 0.04) above.
export function defaultChart( n = 32 ) {

	const nov = Array.from( { length: n }, ( _, i ) => ( i + 0.5 ) / n );
	const rows = [];
	for ( const material of [ { metalness: 1, color: [ 1, 0.5, 0.2 ] }, { metalness: 0, color: [ 0, 0, 0 ] } ] ) {

		for ( let j = 0; j < n / 2; j ++ ) rows.push( { ...material, roughness: 0.05 + 0.95 * j / ( n / 2 - 1 ) } );

	}
	return { nov, rows };

}

export function expose( furnace, prepare = () => {} ) {

	window.furnace = async ( spec ) => {

		await prepare( spec );
		const result = await furnace( spec );
		if ( result.dispose ) result.dispose();
		return { width: result.width, height: result.height, pixels: Array.from( result.pixels ), renderer: result.renderer,
			info: result.info };

	};
	window.furnaceDemo = async () => {

		const spec = defaultChart();
		await prepare( spec );
		const result = await furnace( spec );
		document.body.appendChild( result.canvas );
		return result;

	};
	window.defaultChart = defaultChart;
	window.furnaceReady = true;
	if ( ! new URLSearchParams( location.search ).has( 'driver' ) && window.parent === window ) window.furnaceDemo();

}
