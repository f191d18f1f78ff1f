<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:brid="http://www.opengis.net/citygml/bridge/2.0" xmlns:tran="http://www.opengis.net/citygml/transportation/2.0" xmlns:frn="http://www.opengis.net/citygml/cityfurniture/2.0" xmlns:wtr="http://www.opengis.net/citygml/waterbody/2.0" xmlns:sch="http://www.ascc.net/xml/schematron" xmlns:veg="http://www.opengis.net/citygml/vegetation/2.0" xmlns:xlink="http://www.w3.org/1999/xlink" xmlns:tun="http://www.opengis.net/citygml/tunnel/2.0" xmlns:tex="http://www.opengis.net/citygml/texturedsurface/2.0" xmlns:gml="http://www.opengis.net/gml" xmlns:gen="http://www.opengis.net/citygml/generics/2.0" xmlns:dem="http://www.opengis.net/citygml/relief/2.0" xmlns:app="http://www.opengis.net/citygml/appearance/2.0" xmlns:luse="http://www.opengis.net/citygml/landuse/2.0" xmlns:xAL="urn:oasis:names:tc:ciq:xsdschema:xAL:2.0" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xmlns:smil20lang="http://www.w3.org/2001/SMIL20/Language" xmlns:pbase="http://www.opengis.net/citygml/profiles/base/2.0" xmlns:smil20="http://www.w3.org/2001/SMIL20/" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:grp="http://www.opengis.net/citygml/cityobjectgroup/2.0">
	<gml:boundedBy>
		<gml:Envelope srsName="EPSG:25833" srsDimension="3">
			<gml:lowerCorner>396800.04 5819400.54 40.35</gml:lowerCorner>
			<gml:upperCorner>396999.55 5819590.91 46.3</gml:upperCorner>
		</gml:Envelope>
	</gml:boundedBy>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>4.18</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>2.89</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396801.75</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819590.41</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.36</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">7.07</veg:height>
			<veg:crownDiameter uom="m">3.5700000000000003</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>3.393715534911038 -1.7320855883502724 0.0 0.0 
2.474407983357532 2.3756008744377266 0.0 0.0 
0.0 0.0 7.07 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry>
						<gml:MultiGeometry gml:id="fme-gen-c879065e-0344-4584-aab5-e3ea51c2af20" srsName="EPSG:25833" srsDimension="3">
							<gml:geometryMember>
								<gml:MultiGeometry>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>2.220446049250313e-16 -0.1157823046505248 0.40000000000000013 1.1102230246251565e-16 -0.3696144473933624 0.4286829060300946 -0.2613568821763651 -0.2613568821763649 0.4286829060300946 -0.08187045275979277 -0.08187045275979277 0.40000000000000013 2.220446049250313e-16 -0.1157823046505248 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.08187045275979277 -0.08187045275979277 0.40000000000000013 -0.2613568821763651 -0.2613568821763649 0.4286829060300946 -0.3696144473933624 0 0.4286829060300946 -0.11578230465052475 0 0.40000000000000013 -0.08187045275979277 -0.08187045275979277 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.34323137503354223 0.3432313750335425 0.4995017412979412 -0.353553390593274 0.3535533905932742 0.6403170178482881 1.1102230246251565e-16 0.5000000000000003 0.6403170178482881 1.1102230246251565e-16 0.4854024656044017 0.4995017412979412 -0.34323137503354223 0.3432313750335425 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 -0.4582388295169337 1.1102230246251565e-16 0.7756571737356703 -0.32402378375441004 0.3240237837544102 0.7756571737356703 -0.353553390593274 0.3535533905932742 0.6403170178482881 -0.5000000000000003 1.1102230246251565e-16 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.2613568821763651 -0.2613568821763649 0.4286829060300946 -0.3432313750335424 -0.3432313750335422 0.4995017412979412 -0.48540246560440165 1.1102230246251565e-16 0.4995017412979412 -0.3696144473933624 0 0.4286829060300946 -0.2613568821763651 -0.2613568821763649 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.34089190337894715 1.1102230246251565e-16 0.8958791428425344 -0.2590778259953599 0 0.9461224706297431 -0.18319568761638733 0.1831956876163875 0.9461224706297431 -0.24104697653084284 0.24104697653084306 0.8958791428425344 -0.34089190337894715 1.1102230246251565e-16 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.32402378375441016 -0.32402378375441 0.7756571737356703 -0.24104697653084295 -0.24104697653084273 0.8958791428425344 -0.34089190337894715 1.1102230246251565e-16 0.8958791428425344 -0.4582388295169337 1.1102230246251565e-16 0.7756571737356703 -0.32402378375441016 -0.32402378375441 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.24104697653084284 0.24104697653084306 0.8958791428425344 -0.18319568761638733 0.1831956876163875 0.9461224706297431 0 0.2590778259953599 0.9461224706297431 0 0.34089190337894726 0.8958791428425344 -0.24104697653084284 0.24104697653084306 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.2590778259953599 0 0.9461224706297431 -0.10226757028252298 1.1102230246251565e-16 1.0000000000000002 -0.07231409244224374 0.07231409244224396 1.0000000000000002 -0.18319568761638733 0.1831956876163875 0.9461224706297431 -0.2590778259953599 0 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.3696144473933624 0.4286829060300946 0 -0.4854024656044016 0.4995017412979412 -0.3432313750335424 -0.3432313750335422 0.4995017412979412 -0.2613568821763651 -0.2613568821763649 0.4286829060300946 1.1102230246251565e-16 -0.3696144473933624 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.3696144473933624 0 0.4286829060300946 -0.48540246560440165 1.1102230246251565e-16 0.4995017412979412 -0.34323137503354223 0.3432313750335425 0.4995017412979412 -0.261356882176365 0.2613568821763652 0.4286829060300946 -0.3696144473933624 0 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.4582388295169337 0.7756571737356703 1.1102230246251565e-16 -0.34089190337894715 0.8958791428425344 -0.24104697653084295 -0.24104697653084273 0.8958791428425344 -0.32402378375441016 -0.32402378375441 0.7756571737356703 1.1102230246251565e-16 -0.4582388295169337 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.08187045275979354 0.08187045275979332 0.40000000000000013 0.2613568821763651 0.2613568821763651 0.4286829060300946 0.3696144473933627 0 0.4286829060300946 0.11578230465052575 0 0.40000000000000013 0.08187045275979354 0.08187045275979332 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.3696144473933627 0.4286829060300946 1.1102230246251565e-16 0.4854024656044017 0.4995017412979412 0.3432313750335423 0.3432313750335423 0.4995017412979412 0.2613568821763651 0.2613568821763651 0.4286829060300946 0 0.3696144473933627 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3240237837544102 0.32402378375441 0.7756571737356703 0.24104697653084295 0.24104697653084295 0.8958791428425344 0.34089190337894726 0 0.8958791428425344 0.45823882951693373 0 0.7756571737356703 0.3240237837544102 0.32402378375441 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.45823882951693373 0 0.7756571737356703 0.34089190337894726 0 0.8958791428425344 0.24104697653084295 -0.2410469765308429 0.8958791428425344 0.3240237837544102 -0.32402378375441016 0.7756571737356703 0.45823882951693373 0 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.35355339059327395 0.3535533905932742 0.6403170178482881 0.3240237837544102 0.32402378375441 0.7756571737356703 0.45823882951693373 0 0.7756571737356703 0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 0.35355339059327395 0.3535533905932742 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.34089190337894726 0 0.8958791428425344 0.2590778259953599 0 0.9461224706297431 0.18319568761638738 -0.18319568761638727 0.9461224706297431 0.24104697653084295 -0.2410469765308429 0.8958791428425344 0.34089190337894726 0 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>2.220446049250313e-16 -0.25907782599535994 0.9461224706297431 2.220446049250313e-16 -0.10226757028252298 1.0000000000000002 -0.07231409244224374 -0.07231409244224374 1.0000000000000002 -0.18319568761638738 -0.18319568761638738 0.9461224706297431 2.220446049250313e-16 -0.25907782599535994 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.353553390593274 0.3535533905932742 0.6403170178482881 -0.32402378375441004 0.3240237837544102 0.7756571737356703 1.1102230246251565e-16 0.45823882951693373 0.7756571737356703 1.1102230246251565e-16 0.5000000000000003 0.6403170178482881 -0.353553390593274 0.3535533905932742 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 0.5000000000000003 0.6403170178482881 1.1102230246251565e-16 0.45823882951693373 0.7756571737356703 0.3240237837544102 0.32402378375441 0.7756571737356703 0.35355339059327395 0.3535533905932742 0.6403170178482881 1.1102230246251565e-16 0.5000000000000003 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.18319568761638738 0.18319568761638738 0.9461224706297431 0.07231408775986736 0.07231408775986725 1.0000000000000002 0.1022675636606426 0 1.0000000000000002 0.2590778259953599 0 0.9461224706297431 0.18319568761638738 0.18319568761638738 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 0.4854024656044017 0.4995017412979412 1.1102230246251565e-16 0.5000000000000003 0.6403170178482881 0.35355339059327395 0.3535533905932742 0.6403170178482881 0.3432313750335423 0.3432313750335423 0.4995017412979412 1.1102230246251565e-16 0.4854024656044017 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.2613568821763651 0.2613568821763651 0.4286829060300946 0.3432313750335423 0.3432313750335423 0.4995017412979412 0.4854024656044017 0 0.4995017412979412 0.3696144473933627 0 0.4286829060300946 0.2613568821763651 0.2613568821763651 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.48540246560440165 1.1102230246251565e-16 0.4995017412979412 -0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 -0.353553390593274 0.3535533905932742 0.6403170178482881 -0.34323137503354223 0.3432313750335425 0.4995017412979412 -0.48540246560440165 1.1102230246251565e-16 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.11578230465052475 0 0.40000000000000013 -0.3696144473933624 0 0.4286829060300946 -0.261356882176365 0.2613568821763652 0.4286829060300946 -0.08187045275979277 0.08187045275979299 0.40000000000000013 -0.11578230465052475 0 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.24104697653084295 -0.2410469765308429 0.8958791428425344 0.18319568761638738 -0.18319568761638727 0.9461224706297431 2.220446049250313e-16 -0.25907782599535994 0.9461224706297431 1.1102230246251565e-16 -0.34089190337894715 0.8958791428425344 0.24104697653084295 -0.2410469765308429 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.18319568761638738 -0.18319568761638727 0.9461224706297431 0.07231408775986736 -0.0723140877598672 1.0000000000000002 2.220446049250313e-16 -0.10226757028252298 1.0000000000000002 2.220446049250313e-16 -0.25907782599535994 0.9461224706297431 0.18319568761638738 -0.18319568761638727 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3432313750335423 0.3432313750335423 0.4995017412979412 0.35355339059327395 0.3535533905932742 0.6403170178482881 0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 0.4854024656044017 0 0.4995017412979412 0.3432313750335423 0.3432313750335423 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>3.3306690738754696e-16 0.11578230465052552 0.40000000000000013 0 0.3696144473933627 0.4286829060300946 0.2613568821763651 0.2613568821763651 0.4286829060300946 0.08187045275979354 0.08187045275979332 0.40000000000000013 3.3306690738754696e-16 0.11578230465052552 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 0.45823882951693373 0.7756571737356703 0 0.34089190337894726 0.8958791428425344 0.24104697653084295 0.24104697653084295 0.8958791428425344 0.3240237837544102 0.32402378375441 0.7756571737356703 1.1102230246251565e-16 0.45823882951693373 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.08187045275979354 -0.08187045275979332 0.40000000000000013 0.2613568821763651 -0.261356882176365 0.4286829060300946 1.1102230246251565e-16 -0.3696144473933624 0.4286829060300946 2.220446049250313e-16 -0.1157823046505248 0.40000000000000013 0.08187045275979354 -0.08187045275979332 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.34089190337894715 0.8958791428425344 2.220446049250313e-16 -0.25907782599535994 0.9461224706297431 -0.18319568761638738 -0.18319568761638738 0.9461224706297431 -0.24104697653084295 -0.24104697653084273 0.8958791428425344 1.1102230246251565e-16 -0.34089190337894715 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.2590778259953599 0.9461224706297431 3.3306690738754696e-16 0.10226756366064238 1.0000000000000002 0.07231408775986736 0.07231408775986725 1.0000000000000002 0.18319568761638738 0.18319568761638738 0.9461224706297431 0 0.2590778259953599 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.3432313750335424 -0.3432313750335422 0.4995017412979412 -0.35355339059327406 -0.3535533905932739 0.6403170178482881 -0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 -0.48540246560440165 1.1102230246251565e-16 0.4995017412979412 -0.3432313750335424 -0.3432313750335422 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.34089190337894726 0.8958791428425344 0 0.2590778259953599 0.9461224706297431 0.18319568761638738 0.18319568761638738 0.9461224706297431 0.24104697653084295 0.24104697653084295 0.8958791428425344 0 0.34089190337894726 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.5000000000000003 0.6403170178482881 1.1102230246251565e-16 -0.4582388295169337 0.7756571737356703 -0.32402378375441016 -0.32402378375441 0.7756571737356703 -0.35355339059327406 -0.3535533905932739 0.6403170178482881 1.1102230246251565e-16 -0.5000000000000003 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.35355339059327395 -0.35355339059327395 0.6403170178482881 0.3240237837544102 -0.32402378375441016 0.7756571737356703 1.1102230246251565e-16 -0.4582388295169337 0.7756571737356703 1.1102230246251565e-16 -0.5000000000000003 0.6403170178482881 0.35355339059327395 -0.35355339059327395 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.4854024656044017 0 0.4995017412979412 0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 0.35355339059327395 -0.35355339059327395 0.6403170178482881 0.3432313750335423 -0.3432313750335423 0.4995017412979412 0.4854024656044017 0 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3696144473933627 0 0.4286829060300946 0.4854024656044017 0 0.4995017412979412 0.3432313750335423 -0.3432313750335423 0.4995017412979412 0.2613568821763651 -0.261356882176365 0.4286829060300946 0.3696144473933627 0 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.11578230465052575 0 0.40000000000000013 0.3696144473933627 0 0.4286829060300946 0.2613568821763651 -0.261356882176365 0.4286829060300946 0.08187045275979354 -0.08187045275979332 0.40000000000000013 0.11578230465052575 0 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 -0.4854024656044016 0.4995017412979412 1.1102230246251565e-16 -0.5000000000000003 0.6403170178482881 -0.35355339059327406 -0.3535533905932739 0.6403170178482881 -0.3432313750335424 -0.3432313750335422 0.4995017412979412 0 -0.4854024656044016 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 0.45823882951693373 0 0.7756571737356703 0.3240237837544102 -0.32402378375441016 0.7756571737356703 0.35355339059327395 -0.35355339059327395 0.6403170178482881 0.5000000000000003 1.1102230246251565e-16 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.18319568761638738 -0.18319568761638738 0.9461224706297431 -0.07231409244224374 -0.07231409244224374 1.0000000000000002 -0.10226757028252298 1.1102230246251565e-16 1.0000000000000002 -0.2590778259953599 0 0.9461224706297431 -0.18319568761638738 -0.18319568761638738 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.18319568761638733 0.1831956876163875 0.9461224706297431 -0.07231409244224374 0.07231409244224396 1.0000000000000002 3.3306690738754696e-16 0.10226756366064238 1.0000000000000002 0 0.2590778259953599 0.9461224706297431 -0.18319568761638733 0.1831956876163875 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.2590778259953599 0 0.9461224706297431 0.1022675636606426 0 1.0000000000000002 0.07231408775986736 -0.0723140877598672 1.0000000000000002 0.18319568761638738 -0.18319568761638727 0.9461224706297431 0.2590778259953599 0 0.9461224706297431</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.2613568821763651 -0.261356882176365 0.4286829060300946 0.3432313750335423 -0.3432313750335423 0.4995017412979412 0 -0.4854024656044016 0.4995017412979412 1.1102230246251565e-16 -0.3696144473933624 0.4286829060300946 0.2613568821763651 -0.261356882176365 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.11578230465052475 0 0.40000000000000013 -0.08187045275979277 0.08187045275979299 0.40000000000000013 3.3306690738754696e-16 0.11578230465052552 0.40000000000000013 0.08187045275979354 0.08187045275979332 0.40000000000000013 0.11578230465052575 0 0.40000000000000013 0.08187045275979354 -0.08187045275979332 0.40000000000000013 2.220446049250313e-16 -0.1157823046505248 0.40000000000000013 -0.08187045275979277 -0.08187045275979277 0.40000000000000013 -0.11578230465052475 0 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
											<gml:interior>
												<gml:LinearRing>
													<gml:posList>0 -0.019999999999999962 0.40000000000000013 0.014142135623731011 -0.0141421356237309 0.40000000000000013 0.02000000000000013 0 0.40000000000000013 0.014142135623731011 0.014142135623731011 0.40000000000000013 0 0.02000000000000013 0.40000000000000013 -0.014142135623730956 0.014142135623731011 0.40000000000000013 -0.020000000000000018 0 0.40000000000000013 -0.014142135623730956 -0.014142135623730956 0.40000000000000013 0 -0.019999999999999962 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:interior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.24104697653084295 0.24104697653084295 0.8958791428425344 0.18319568761638738 0.18319568761638738 0.9461224706297431 0.2590778259953599 0 0.9461224706297431 0.34089190337894726 0 0.8958791428425344 0.24104697653084295 0.24104697653084295 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.07231408775986736 0.07231408775986725 1.0000000000000002 3.3306690738754696e-16 0.10226756366064238 1.0000000000000002 -0.07231409244224374 0.07231409244224396 1.0000000000000002 -0.10226757028252298 1.1102230246251565e-16 1.0000000000000002 -0.07231409244224374 -0.07231409244224374 1.0000000000000002 2.220446049250313e-16 -0.10226757028252298 1.0000000000000002 0.07231408775986736 -0.0723140877598672 1.0000000000000002 0.1022675636606426 0 1.0000000000000002 0.07231408775986736 0.07231408775986725 1.0000000000000002</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3432313750335423 -0.3432313750335423 0.4995017412979412 0.35355339059327395 -0.35355339059327395 0.6403170178482881 1.1102230246251565e-16 -0.5000000000000003 0.6403170178482881 0 -0.4854024656044016 0.4995017412979412 0.3432313750335423 -0.3432313750335423 0.4995017412979412</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.35355339059327406 -0.3535533905932739 0.6403170178482881 -0.32402378375441016 -0.32402378375441 0.7756571737356703 -0.4582388295169337 1.1102230246251565e-16 0.7756571737356703 -0.5000000000000003 1.1102230246251565e-16 0.6403170178482881 -0.35355339059327406 -0.3535533905932739 0.6403170178482881</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.014142135623731011 -0.0141421356237309 0.40000000000000013 0 -0.019999999999999962 0.40000000000000013 0 -0.019999999999999962 -1.127986593019159e-16 0.014142135623731011 -0.0141421356237309 -1.127986593019159e-16 0.014142135623731011 -0.0141421356237309 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 -0.019999999999999962 0.40000000000000013 -0.014142135623730956 -0.014142135623730956 0.40000000000000013 -0.014142135623730956 -0.014142135623730956 -1.127986593019159e-16 0 -0.019999999999999962 -1.127986593019159e-16 0 -0.019999999999999962 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.014142135623730956 0.014142135623731011 0.40000000000000013 0 0.02000000000000013 0.40000000000000013 0 0.02000000000000013 -1.127986593019159e-16 -0.014142135623730956 0.014142135623731011 -1.127986593019159e-16 -0.014142135623730956 0.014142135623731011 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.02000000000000013 0.40000000000000013 0.014142135623731011 0.014142135623731011 0.40000000000000013 0.014142135623731011 0.014142135623731011 -1.127986593019159e-16 0 0.02000000000000013 -1.127986593019159e-16 0 0.02000000000000013 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.014142135623731011 -0.0141421356237309 -1.127986593019159e-16 0 -0.019999999999999962 -1.127986593019159e-16 -0.014142135623730956 -0.014142135623730956 -1.127986593019159e-16 -0.020000000000000018 0 -1.127986593019159e-16 -0.014142135623730956 0.014142135623731011 -1.127986593019159e-16 0 0.02000000000000013 -1.127986593019159e-16 0.014142135623731011 0.014142135623731011 -1.127986593019159e-16 0.02000000000000013 0 -1.127986593019159e-16 0.014142135623731011 -0.0141421356237309 -1.127986593019159e-16</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.02000000000000013 0 0.40000000000000013 0.014142135623731011 -0.0141421356237309 0.40000000000000013 0.014142135623731011 -0.0141421356237309 -1.127986593019159e-16 0.02000000000000013 0 -1.127986593019159e-16 0.02000000000000013 0 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.014142135623730956 -0.014142135623730956 0.40000000000000013 -0.020000000000000018 0 0.40000000000000013 -0.020000000000000018 0 -1.127986593019159e-16 -0.014142135623730956 -0.014142135623730956 -1.127986593019159e-16 -0.014142135623730956 -0.014142135623730956 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.014142135623731011 0.014142135623731011 0.40000000000000013 0.02000000000000013 0 0.40000000000000013 0.02000000000000013 0 -1.127986593019159e-16 0.014142135623731011 0.014142135623731011 -1.127986593019159e-16 0.014142135623731011 0.014142135623731011 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.020000000000000018 0 0.40000000000000013 -0.014142135623730956 0.014142135623731011 0.40000000000000013 -0.014142135623730956 0.014142135623731011 -1.127986593019159e-16 -0.020000000000000018 0 -1.127986593019159e-16 -0.020000000000000018 0 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3240237837544102 -0.32402378375441016 0.7756571737356703 0.24104697653084295 -0.2410469765308429 0.8958791428425344 1.1102230246251565e-16 -0.34089190337894715 0.8958791428425344 1.1102230246251565e-16 -0.4582388295169337 0.7756571737356703 0.3240237837544102 -0.32402378375441016 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.32402378375441004 0.3240237837544102 0.7756571737356703 -0.24104697653084284 0.24104697653084306 0.8958791428425344 0 0.34089190337894726 0.8958791428425344 1.1102230246251565e-16 0.45823882951693373 0.7756571737356703 -0.32402378375441004 0.3240237837544102 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.261356882176365 0.2613568821763652 0.4286829060300946 -0.34323137503354223 0.3432313750335425 0.4995017412979412 1.1102230246251565e-16 0.4854024656044017 0.4995017412979412 0 0.3696144473933627 0.4286829060300946 -0.261356882176365 0.2613568821763652 0.4286829060300946</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.24104697653084295 -0.24104697653084273 0.8958791428425344 -0.18319568761638738 -0.18319568761638738 0.9461224706297431 -0.2590778259953599 0 0.9461224706297431 -0.34089190337894715 1.1102230246251565e-16 0.8958791428425344 -0.24104697653084295 -0.24104697653084273 0.8958791428425344</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.4582388295169337 1.1102230246251565e-16 0.7756571737356703 -0.34089190337894715 1.1102230246251565e-16 0.8958791428425344 -0.24104697653084284 0.24104697653084306 0.8958791428425344 -0.32402378375441004 0.3240237837544102 0.7756571737356703 -0.4582388295169337 1.1102230246251565e-16 0.7756571737356703</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.08187045275979277 0.08187045275979299 0.40000000000000013 -0.261356882176365 0.2613568821763652 0.4286829060300946 0 0.3696144473933627 0.4286829060300946 3.3306690738754696e-16 0.11578230465052552 0.40000000000000013 -0.08187045275979277 0.08187045275979299 0.40000000000000013</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
								</gml:MultiGeometry>
							</gml:geometryMember>
						</gml:MultiGeometry>
					</core:relativeGMLGeometry>
					<core:referencePoint>
						<gml:Point>
							<gml:pos>396801.75 5819590.41 43.36</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>6.61</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>4.05</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396915.8</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819577.96</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>45.3</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">10.66</veg:height>
			<veg:crownDiameter uom="m">5.63</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>7.698299240648595 -0.990884665940771 0.0 0.0 
2.551134806596715 2.9900915669596886 0.0 0.0 
0.0 0.0 10.66 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-c879065e-0344-4584-aab5-e3ea51c2af20"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396915.8 5819577.96 45.3</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>13.41</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>1.6800000000000002</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396915.47</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819574.02</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.63</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">15.09</veg:height>
			<veg:crownDiameter uom="m">8.01</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>4.71962117135049 -5.4298711214602795 0.0 0.0 
8.62288095702012 2.9719689776866263 0.0 0.0 
0.0 0.0 15.09 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry>
						<gml:MultiGeometry gml:id="fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826" srsName="EPSG:25833" srsDimension="3">
							<gml:geometryMember>
								<gml:MultiGeometry>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.014142135623731011 -0.0141421356237309 -5.639932965095795e-18 0 -0.019999999999999962 -5.639932965095795e-18 -0.014142135623730956 -0.014142135623730956 -5.639932965095795e-18 -0.020000000000000018 0 -5.639932965095795e-18 -0.014142135623730956 0.014142135623731011 -5.639932965095795e-18 0 0.02000000000000013 -5.639932965095795e-18 0.014142135623731011 0.014142135623731011 -5.639932965095795e-18 0.02000000000000013 0 -5.639932965095795e-18 0.014142135623731011 -0.0141421356237309 -5.639932965095795e-18</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.02000000000000013 0.09999999999999995 0.014142135623731011 0.014142135623731011 0.09999999999999995 0.014142135623731011 0.014142135623731011 -5.639932965095795e-18 0 0.02000000000000013 -5.639932965095795e-18 0 0.02000000000000013 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.014142135623731011 0.014142135623731011 0.09999999999999995 0.02000000000000013 0 0.09999999999999995 0.02000000000000013 0 -5.639932965095795e-18 0.014142135623731011 0.014142135623731011 -5.639932965095795e-18 0.014142135623731011 0.014142135623731011 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.02000000000000013 0 0.09999999999999995 0.014142135623731011 -0.0141421356237309 0.09999999999999995 0.014142135623731011 -0.0141421356237309 -5.639932965095795e-18 0.02000000000000013 0 -5.639932965095795e-18 0.02000000000000013 0 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.014142135623730956 0.014142135623731011 0.09999999999999995 0 0.02000000000000013 0.09999999999999995 0 0.02000000000000013 -5.639932965095795e-18 -0.014142135623730956 0.014142135623731011 -5.639932965095795e-18 -0.014142135623730956 0.014142135623731011 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.014142135623730956 -0.014142135623730956 0.09999999999999995 -0.020000000000000018 0 0.09999999999999995 -0.020000000000000018 0 -5.639932965095795e-18 -0.014142135623730956 -0.014142135623730956 -5.639932965095795e-18 -0.014142135623730956 -0.014142135623730956 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.014142135623731011 -0.0141421356237309 0.09999999999999995 0 -0.019999999999999962 0.09999999999999995 0 -0.019999999999999962 -5.639932965095795e-18 0.014142135623731011 -0.0141421356237309 -5.639932965095795e-18 0.014142135623731011 -0.0141421356237309 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 -0.019999999999999962 0.09999999999999995 -0.014142135623730956 -0.014142135623730956 0.09999999999999995 -0.014142135623730956 -0.014142135623730956 -5.639932965095795e-18 0 -0.019999999999999962 -5.639932965095795e-18 0 -0.019999999999999962 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.020000000000000018 0 0.09999999999999995 -0.014142135623730956 0.014142135623731011 0.09999999999999995 -0.014142135623730956 0.014142135623731011 -5.639932965095795e-18 -0.020000000000000018 0 -5.639932965095795e-18 -0.020000000000000018 0 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.2613568821763651 -0.2613568821763649 0.14302435904514163 -0.3432313750335424 -0.3432313750335422 0.2492526119469115 -0.48540246560440165 1.1102230246251565e-16 0.2492526119469115 -0.3696144473933624 0 0.14302435904514163 -0.2613568821763651 -0.2613568821763649 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.24104697653084284 0.24104697653084306 0.8438187142638012 -0.18319568761638733 0.1831956876163875 0.9191837059446138 0 0.2590778259953599 0.9191837059446138 0 0.34089190337894726 0.8438187142638012 -0.24104697653084284 0.24104697653084306 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.34089190337894715 1.1102230246251565e-16 0.8438187142638012 -0.2590778259953599 0 0.9191837059446138 -0.18319568761638733 0.1831956876163875 0.9191837059446138 -0.24104697653084284 0.24104697653084306 0.8438187142638012 -0.34089190337894715 1.1102230246251565e-16 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.08187045275979277 -0.08187045275979277 0.09999999999999995 -0.2613568821763651 -0.2613568821763649 0.14302435904514163 -0.3696144473933624 0 0.14302435904514163 -0.11578230465052475 0 0.09999999999999995 -0.08187045275979277 -0.08187045275979277 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.2590778259953599 0 0.9191837059446138 -0.10226757028252298 1.1102230246251565e-16 1 -0.07231409244224374 0.07231409244224396 1 -0.18319568761638733 0.1831956876163875 0.9191837059446138 -0.2590778259953599 0 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.32402378375441004 0.3240237837544102 0.6634857606035052 -0.24104697653084284 0.24104697653084306 0.8438187142638012 0 0.34089190337894726 0.8438187142638012 1.1102230246251565e-16 0.45823882951693373 0.6634857606035052 -0.32402378375441004 0.3240237837544102 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.4582388295169337 1.1102230246251565e-16 0.6634857606035052 -0.34089190337894715 1.1102230246251565e-16 0.8438187142638012 -0.24104697653084284 0.24104697653084306 0.8438187142638012 -0.32402378375441004 0.3240237837544102 0.6634857606035052 -0.4582388295169337 1.1102230246251565e-16 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.34323137503354223 0.3432313750335425 0.2492526119469115 -0.353553390593274 0.3535533905932742 0.460475526772432 1.1102230246251565e-16 0.5000000000000003 0.460475526772432 1.1102230246251565e-16 0.4854024656044017 0.2492526119469115 -0.34323137503354223 0.3432313750335425 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.48540246560440165 1.1102230246251565e-16 0.2492526119469115 -0.5000000000000003 1.1102230246251565e-16 0.460475526772432 -0.353553390593274 0.3535533905932742 0.460475526772432 -0.34323137503354223 0.3432313750335425 0.2492526119469115 -0.48540246560440165 1.1102230246251565e-16 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.5000000000000003 1.1102230246251565e-16 0.460475526772432 -0.4582388295169337 1.1102230246251565e-16 0.6634857606035052 -0.32402378375441004 0.3240237837544102 0.6634857606035052 -0.353553390593274 0.3535533905932742 0.460475526772432 -0.5000000000000003 1.1102230246251565e-16 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.08187045275979277 0.08187045275979299 0.09999999999999995 -0.261356882176365 0.2613568821763652 0.14302435904514163 0 0.3696144473933627 0.14302435904514163 3.3306690738754696e-16 0.11578230465052552 0.09999999999999995 -0.08187045275979277 0.08187045275979299 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.261356882176365 0.2613568821763652 0.14302435904514163 -0.34323137503354223 0.3432313750335425 0.2492526119469115 1.1102230246251565e-16 0.4854024656044017 0.2492526119469115 0 0.3696144473933627 0.14302435904514163 -0.261356882176365 0.2613568821763652 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.3696144473933624 0 0.14302435904514163 -0.48540246560440165 1.1102230246251565e-16 0.2492526119469115 -0.34323137503354223 0.3432313750335425 0.2492526119469115 -0.261356882176365 0.2613568821763652 0.14302435904514163 -0.3696144473933624 0 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.24104697653084295 -0.24104697653084273 0.8438187142638012 -0.18319568761638738 -0.18319568761638738 0.9191837059446138 -0.2590778259953599 0 0.9191837059446138 -0.34089190337894715 1.1102230246251565e-16 0.8438187142638012 -0.24104697653084295 -0.24104697653084273 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.3696144473933624 0.14302435904514163 0 -0.4854024656044016 0.2492526119469115 -0.3432313750335424 -0.3432313750335422 0.2492526119469115 -0.2613568821763651 -0.2613568821763649 0.14302435904514163 1.1102230246251565e-16 -0.3696144473933624 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.32402378375441016 -0.32402378375441 0.6634857606035052 -0.24104697653084295 -0.24104697653084273 0.8438187142638012 -0.34089190337894715 1.1102230246251565e-16 0.8438187142638012 -0.4582388295169337 1.1102230246251565e-16 0.6634857606035052 -0.32402378375441016 -0.32402378375441 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.11578230465052475 0 0.09999999999999995 -0.3696144473933624 0 0.14302435904514163 -0.261356882176365 0.2613568821763652 0.14302435904514163 -0.08187045275979277 0.08187045275979299 0.09999999999999995 -0.11578230465052475 0 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.35355339059327406 -0.3535533905932739 0.460475526772432 -0.32402378375441016 -0.32402378375441 0.6634857606035052 -0.4582388295169337 1.1102230246251565e-16 0.6634857606035052 -0.5000000000000003 1.1102230246251565e-16 0.460475526772432 -0.35355339059327406 -0.3535533905932739 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.35355339059327395 -0.35355339059327395 0.460475526772432 0.3240237837544102 -0.32402378375441016 0.6634857606035052 1.1102230246251565e-16 -0.4582388295169337 0.6634857606035052 1.1102230246251565e-16 -0.5000000000000003 0.460475526772432 0.35355339059327395 -0.35355339059327395 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 -0.4854024656044016 0.2492526119469115 1.1102230246251565e-16 -0.5000000000000003 0.460475526772432 -0.35355339059327406 -0.3535533905932739 0.460475526772432 -0.3432313750335424 -0.3432313750335422 0.2492526119469115 0 -0.4854024656044016 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.18319568761638738 -0.18319568761638738 0.9191837059446138 -0.07231409244224374 -0.07231409244224374 1 -0.10226757028252298 1.1102230246251565e-16 1 -0.2590778259953599 0 0.9191837059446138 -0.18319568761638738 -0.18319568761638738 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3432313750335423 -0.3432313750335423 0.2492526119469115 0.35355339059327395 -0.35355339059327395 0.460475526772432 1.1102230246251565e-16 -0.5000000000000003 0.460475526772432 0 -0.4854024656044016 0.2492526119469115 0.3432313750335423 -0.3432313750335423 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.2613568821763651 -0.261356882176365 0.14302435904514163 0.3432313750335423 -0.3432313750335423 0.2492526119469115 0 -0.4854024656044016 0.2492526119469115 1.1102230246251565e-16 -0.3696144473933624 0.14302435904514163 0.2613568821763651 -0.261356882176365 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.18319568761638733 0.1831956876163875 0.9191837059446138 -0.07231409244224374 0.07231409244224396 1 3.3306690738754696e-16 0.10226756366064238 1 0 0.2590778259953599 0.9191837059446138 -0.18319568761638733 0.1831956876163875 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>2.220446049250313e-16 -0.1157823046505248 0.09999999999999995 1.1102230246251565e-16 -0.3696144473933624 0.14302435904514163 -0.2613568821763651 -0.2613568821763649 0.14302435904514163 -0.08187045275979277 -0.08187045275979277 0.09999999999999995 2.220446049250313e-16 -0.1157823046505248 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.24104697653084295 -0.2410469765308429 0.8438187142638012 0.18319568761638738 -0.18319568761638727 0.9191837059446138 2.220446049250313e-16 -0.25907782599535994 0.9191837059446138 1.1102230246251565e-16 -0.34089190337894715 0.8438187142638012 0.24104697653084295 -0.2410469765308429 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3696144473933627 0 0.14302435904514163 0.4854024656044017 0 0.2492526119469115 0.3432313750335423 -0.3432313750335423 0.2492526119469115 0.2613568821763651 -0.261356882176365 0.14302435904514163 0.3696144473933627 0 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.4854024656044017 0 0.2492526119469115 0.5000000000000003 1.1102230246251565e-16 0.460475526772432 0.35355339059327395 -0.35355339059327395 0.460475526772432 0.3432313750335423 -0.3432313750335423 0.2492526119469115 0.4854024656044017 0 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.11578230465052575 0 0.09999999999999995 0.3696144473933627 0 0.14302435904514163 0.2613568821763651 -0.261356882176365 0.14302435904514163 0.08187045275979354 -0.08187045275979332 0.09999999999999995 0.11578230465052575 0 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3240237837544102 -0.32402378375441016 0.6634857606035052 0.24104697653084295 -0.2410469765308429 0.8438187142638012 1.1102230246251565e-16 -0.34089190337894715 0.8438187142638012 1.1102230246251565e-16 -0.4582388295169337 0.6634857606035052 0.3240237837544102 -0.32402378375441016 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.07231408775986736 0.07231408775986725 1 3.3306690738754696e-16 0.10226756366064238 1 -0.07231409244224374 0.07231409244224396 1 -0.10226757028252298 1.1102230246251565e-16 1 -0.07231409244224374 -0.07231409244224374 1 2.220446049250313e-16 -0.10226757028252298 1 0.07231408775986736 -0.0723140877598672 1 0.1022675636606426 0 1 0.07231408775986736 0.07231408775986725 1</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.5000000000000003 1.1102230246251565e-16 0.460475526772432 0.45823882951693373 0 0.6634857606035052 0.3240237837544102 -0.32402378375441016 0.6634857606035052 0.35355339059327395 -0.35355339059327395 0.460475526772432 0.5000000000000003 1.1102230246251565e-16 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.08187045275979354 -0.08187045275979332 0.09999999999999995 0.2613568821763651 -0.261356882176365 0.14302435904514163 1.1102230246251565e-16 -0.3696144473933624 0.14302435904514163 2.220446049250313e-16 -0.1157823046505248 0.09999999999999995 0.08187045275979354 -0.08187045275979332 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.18319568761638738 -0.18319568761638727 0.9191837059446138 0.07231408775986736 -0.0723140877598672 1 2.220446049250313e-16 -0.10226757028252298 1 2.220446049250313e-16 -0.25907782599535994 0.9191837059446138 0.18319568761638738 -0.18319568761638727 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 0.5000000000000003 0.460475526772432 1.1102230246251565e-16 0.45823882951693373 0.6634857606035052 0.3240237837544102 0.32402378375441 0.6634857606035052 0.35355339059327395 0.3535533905932742 0.460475526772432 1.1102230246251565e-16 0.5000000000000003 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.5000000000000003 0.460475526772432 1.1102230246251565e-16 -0.4582388295169337 0.6634857606035052 -0.32402378375441016 -0.32402378375441 0.6634857606035052 -0.35355339059327406 -0.3535533905932739 0.460475526772432 1.1102230246251565e-16 -0.5000000000000003 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>2.220446049250313e-16 -0.25907782599535994 0.9191837059446138 2.220446049250313e-16 -0.10226757028252298 1 -0.07231409244224374 -0.07231409244224374 1 -0.18319568761638738 -0.18319568761638738 0.9191837059446138 2.220446049250313e-16 -0.25907782599535994 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.34089190337894715 0.8438187142638012 2.220446049250313e-16 -0.25907782599535994 0.9191837059446138 -0.18319568761638738 -0.18319568761638738 0.9191837059446138 -0.24104697653084295 -0.24104697653084273 0.8438187142638012 1.1102230246251565e-16 -0.34089190337894715 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 0.45823882951693373 0.6634857606035052 0 0.34089190337894726 0.8438187142638012 0.24104697653084295 0.24104697653084295 0.8438187142638012 0.3240237837544102 0.32402378375441 0.6634857606035052 1.1102230246251565e-16 0.45823882951693373 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.34089190337894726 0.8438187142638012 0 0.2590778259953599 0.9191837059446138 0.18319568761638738 0.18319568761638738 0.9191837059446138 0.24104697653084295 0.24104697653084295 0.8438187142638012 0 0.34089190337894726 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 -0.4582388295169337 0.6634857606035052 1.1102230246251565e-16 -0.34089190337894715 0.8438187142638012 -0.24104697653084295 -0.24104697653084273 0.8438187142638012 -0.32402378375441016 -0.32402378375441 0.6634857606035052 1.1102230246251565e-16 -0.4582388295169337 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.2590778259953599 0.9191837059446138 3.3306690738754696e-16 0.10226756366064238 1 0.07231408775986736 0.07231408775986725 1 0.18319568761638738 0.18319568761638738 0.9191837059446138 0 0.2590778259953599 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>1.1102230246251565e-16 0.4854024656044017 0.2492526119469115 1.1102230246251565e-16 0.5000000000000003 0.460475526772432 0.35355339059327395 0.3535533905932742 0.460475526772432 0.3432313750335423 0.3432313750335423 0.2492526119469115 1.1102230246251565e-16 0.4854024656044017 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.45823882951693373 0 0.6634857606035052 0.34089190337894726 0 0.8438187142638012 0.24104697653084295 -0.2410469765308429 0.8438187142638012 0.3240237837544102 -0.32402378375441016 0.6634857606035052 0.45823882951693373 0 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.34089190337894726 0 0.8438187142638012 0.2590778259953599 0 0.9191837059446138 0.18319568761638738 -0.18319568761638727 0.9191837059446138 0.24104697653084295 -0.2410469765308429 0.8438187142638012 0.34089190337894726 0 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3432313750335423 0.3432313750335423 0.2492526119469115 0.35355339059327395 0.3535533905932742 0.460475526772432 0.5000000000000003 1.1102230246251565e-16 0.460475526772432 0.4854024656044017 0 0.2492526119469115 0.3432313750335423 0.3432313750335423 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.3432313750335424 -0.3432313750335422 0.2492526119469115 -0.35355339059327406 -0.3535533905932739 0.460475526772432 -0.5000000000000003 1.1102230246251565e-16 0.460475526772432 -0.48540246560440165 1.1102230246251565e-16 0.2492526119469115 -0.3432313750335424 -0.3432313750335422 0.2492526119469115</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.2613568821763651 0.2613568821763651 0.14302435904514163 0.3432313750335423 0.3432313750335423 0.2492526119469115 0.4854024656044017 0 0.2492526119469115 0.3696144473933627 0 0.14302435904514163 0.2613568821763651 0.2613568821763651 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.35355339059327395 0.3535533905932742 0.460475526772432 0.3240237837544102 0.32402378375441 0.6634857606035052 0.45823882951693373 0 0.6634857606035052 0.5000000000000003 1.1102230246251565e-16 0.460475526772432 0.35355339059327395 0.3535533905932742 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.353553390593274 0.3535533905932742 0.460475526772432 -0.32402378375441004 0.3240237837544102 0.6634857606035052 1.1102230246251565e-16 0.45823882951693373 0.6634857606035052 1.1102230246251565e-16 0.5000000000000003 0.460475526772432 -0.353553390593274 0.3535533905932742 0.460475526772432</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>3.3306690738754696e-16 0.11578230465052552 0.09999999999999995 0 0.3696144473933627 0.14302435904514163 0.2613568821763651 0.2613568821763651 0.14302435904514163 0.08187045275979354 0.08187045275979332 0.09999999999999995 3.3306690738754696e-16 0.11578230465052552 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.08187045275979354 0.08187045275979332 0.09999999999999995 0.2613568821763651 0.2613568821763651 0.14302435904514163 0.3696144473933627 0 0.14302435904514163 0.11578230465052575 0 0.09999999999999995 0.08187045275979354 0.08187045275979332 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0 0.3696144473933627 0.14302435904514163 1.1102230246251565e-16 0.4854024656044017 0.2492526119469115 0.3432313750335423 0.3432313750335423 0.2492526119469115 0.2613568821763651 0.2613568821763651 0.14302435904514163 0 0.3696144473933627 0.14302435904514163</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.3240237837544102 0.32402378375441 0.6634857606035052 0.24104697653084295 0.24104697653084295 0.8438187142638012 0.34089190337894726 0 0.8438187142638012 0.45823882951693373 0 0.6634857606035052 0.3240237837544102 0.32402378375441 0.6634857606035052</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.18319568761638738 0.18319568761638738 0.9191837059446138 0.07231408775986736 0.07231408775986725 1 0.1022675636606426 0 1 0.2590778259953599 0 0.9191837059446138 0.18319568761638738 0.18319568761638738 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>-0.11578230465052475 0 0.09999999999999995 -0.08187045275979277 0.08187045275979299 0.09999999999999995 3.3306690738754696e-16 0.11578230465052552 0.09999999999999995 0.08187045275979354 0.08187045275979332 0.09999999999999995 0.11578230465052575 0 0.09999999999999995 0.08187045275979354 -0.08187045275979332 0.09999999999999995 2.220446049250313e-16 -0.1157823046505248 0.09999999999999995 -0.08187045275979277 -0.08187045275979277 0.09999999999999995 -0.11578230465052475 0 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
											<gml:interior>
												<gml:LinearRing>
													<gml:posList>0 -0.019999999999999962 0.09999999999999995 0.014142135623731011 -0.0141421356237309 0.09999999999999995 0.02000000000000013 0 0.09999999999999995 0.014142135623731011 0.014142135623731011 0.09999999999999995 0 0.02000000000000013 0.09999999999999995 -0.014142135623730956 0.014142135623731011 0.09999999999999995 -0.020000000000000018 0 0.09999999999999995 -0.014142135623730956 -0.014142135623730956 0.09999999999999995 0 -0.019999999999999962 0.09999999999999995</gml:posList>
												</gml:LinearRing>
											</gml:interior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.2590778259953599 0 0.9191837059446138 0.1022675636606426 0 1 0.07231408775986736 -0.0723140877598672 1 0.18319568761638738 -0.18319568761638727 0.9191837059446138 0.2590778259953599 0 0.9191837059446138</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
									<gml:geometryMember>
										<gml:Polygon>
											<gml:exterior>
												<gml:LinearRing>
													<gml:posList>0.24104697653084295 0.24104697653084295 0.8438187142638012 0.18319568761638738 0.18319568761638738 0.9191837059446138 0.2590778259953599 0 0.9191837059446138 0.34089190337894726 0 0.8438187142638012 0.24104697653084295 0.24104697653084295 0.8438187142638012</gml:posList>
												</gml:LinearRing>
											</gml:exterior>
										</gml:Polygon>
									</gml:geometryMember>
								</gml:MultiGeometry>
							</gml:geometryMember>
						</gml:MultiGeometry>
					</core:relativeGMLGeometry>
					<core:referencePoint>
						<gml:Point>
							<gml:pos>396915.47 5819574.02 43.63</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>19.55</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>1.1</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396982.28</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819572.19</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>44.9</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">20.65</veg:height>
			<veg:crownDiameter uom="m">13.85</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>15.740865573021848 -3.9911042508836934 0.0 0.0 
6.287101956550056 9.99243147880325 0.0 0.0 
0.0 0.0 20.65 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396982.28 5819572.19 44.9</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>13.75</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>5.32</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396805.48</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819572.33</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.03</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">19.07</veg:height>
			<veg:crownDiameter uom="m">13.73</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>-11.356680901793927 -8.065503268068516 0.0 0.0 
11.270572252322818 -8.12712477034628 0.0 0.0 
0.0 0.0 19.07 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry>
						<gml:MultiGeometry gml:id="fme-gen-9749d372-fda4-40fc-8a08-c90d60053563" srsName="EPSG:25833" srsDimension="3">
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.3432313750335423 0.3432313750335423 0.416085364847598 0.35355339059327395 0.3535533905932741 0.5803698541563361 0.5000000000000003 9.023892744153272e-17 0.5803698541563361 0.4854024656044017 0 0.416085364847598 0.3432313750335423 0.3432313750335423 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>2.7071678232459814e-16 0.11578230465052547 0.3000000000000001 0 0.36961444739336263 0.33346339036844364 0.2613568821763651 0.2613568821763651 0.33346339036844364 0.08187045275979352 0.08187045275979334 0.3000000000000001 2.7071678232459814e-16 0.11578230465052547 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0 0.3408919033789472 0.8785256666496232 0 0.25907782599535994 0.9371428824013666 0.18319568761638738 0.18319568761638738 0.9371428824013666 0.24104697653084292 0.24104697653084292 0.8785256666496232 0 0.3408919033789472 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0 0.25907782599535994 0.9371428824013666 2.7071678232459814e-16 0.10226756366064235 1.0000000000000002 0.0723140877598673 0.07231408775986721 1.0000000000000002 0.18319568761638738 0.18319568761638738 0.9371428824013666 0 0.25907782599535994 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.08187045275979352 -0.08187045275979334 0.3000000000000001 0.2613568821763651 -0.26135688217636505 0.33346339036844364 9.023892744153272e-17 -0.3696144473933624 0.33346339036844364 1.8047785488306544e-16 -0.11578230465052484 0.3000000000000001 0.08187045275979352 -0.08187045275979334 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 -0.34089190337894715 0.8785256666496232 1.8047785488306544e-16 -0.25907782599535994 0.9371428824013666 -0.18319568761638738 -0.18319568761638738 0.9371428824013666 -0.24104697653084298 -0.24104697653084275 0.8785256666496232 9.023892744153272e-17 -0.34089190337894715 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.3432313750335424 -0.3432313750335422 0.416085364847598 -0.3535533905932741 -0.35355339059327395 0.5803698541563361 -0.5000000000000003 9.023892744153272e-17 0.5803698541563361 -0.4854024656044017 9.023892744153272e-17 0.416085364847598 -0.3432313750335424 -0.3432313750335422 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 -0.4582388295169337 0.7382667026916152 9.023892744153272e-17 -0.34089190337894715 0.8785256666496232 -0.24104697653084298 -0.24104697653084275 0.8785256666496232 -0.32402378375441016 -0.32402378375441 0.7382667026916152 9.023892744153272e-17 -0.4582388295169337 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.18319568761638738 -0.1831956876163873 0.9371428824013666 0.0723140877598673 -0.07231408775986721 1.0000000000000002 1.8047785488306544e-16 -0.10226757028252302 1.0000000000000002 1.8047785488306544e-16 -0.25907782599535994 0.9371428824013666 0.18319568761638738 -0.1831956876163873 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>1.8047785488306544e-16 -0.25907782599535994 0.9371428824013666 1.8047785488306544e-16 -0.10226757028252302 1.0000000000000002 -0.07231409244224378 -0.07231409244224378 1.0000000000000002 -0.18319568761638738 -0.18319568761638738 0.9371428824013666 1.8047785488306544e-16 -0.25907782599535994 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.2613568821763651 0.2613568821763651 0.33346339036844364 0.3432313750335423 0.3432313750335423 0.416085364847598 0.4854024656044017 0 0.416085364847598 0.36961444739336263 0 0.33346339036844364 0.2613568821763651 0.2613568821763651 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.353553390593274 0.3535533905932741 0.5803698541563361 -0.3240237837544101 0.32402378375441016 0.7382667026916152 9.023892744153272e-17 0.4582388295169337 0.7382667026916152 9.023892744153272e-17 0.5000000000000003 0.5803698541563361 -0.353553390593274 0.3535533905932741 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 -0.5000000000000003 0.5803698541563361 9.023892744153272e-17 -0.4582388295169337 0.7382667026916152 -0.32402378375441016 -0.32402378375441 0.7382667026916152 -0.3535533905932741 -0.35355339059327395 0.5803698541563361 9.023892744153272e-17 -0.5000000000000003 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.3408919033789472 0 0.8785256666496232 0.25907782599535983 0 0.9371428824013666 0.18319568761638738 -0.1831956876163873 0.9371428824013666 0.24104697653084292 -0.24104697653084292 0.8785256666496232 0.3408919033789472 0 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.35355339059327395 0.3535533905932741 0.5803698541563361 0.32402378375441016 0.32402378375441 0.7382667026916152 0.4582388295169337 0 0.7382667026916152 0.5000000000000003 9.023892744153272e-17 0.5803698541563361 0.35355339059327395 0.3535533905932741 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 0.4582388295169337 0.7382667026916152 0 0.3408919033789472 0.8785256666496232 0.24104697653084292 0.24104697653084292 0.8785256666496232 0.32402378375441016 0.32402378375441 0.7382667026916152 9.023892744153272e-17 0.4582388295169337 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.3240237837544101 0.32402378375441016 0.7382667026916152 -0.24104697653084284 0.24104697653084303 0.8785256666496232 0 0.3408919033789472 0.8785256666496232 9.023892744153272e-17 0.4582388295169337 0.7382667026916152 -0.3240237837544101 0.32402378375441016 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.0818704527597928 0.08187045275979297 0.3000000000000001 -0.261356882176365 0.26135688217636516 0.33346339036844364 0 0.36961444739336263 0.33346339036844364 2.7071678232459814e-16 0.11578230465052547 0.3000000000000001 -0.0818704527597928 0.08187045275979297 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.261356882176365 0.26135688217636516 0.33346339036844364 -0.34323137503354223 0.3432313750335425 0.416085364847598 9.023892744153272e-17 0.4854024656044017 0.416085364847598 0 0.36961444739336263 0.33346339036844364 -0.261356882176365 0.26135688217636516 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.4582388295169337 9.023892744153272e-17 0.7382667026916152 -0.34089190337894715 9.023892744153272e-17 0.8785256666496232 -0.24104697653084284 0.24104697653084303 0.8785256666496232 -0.3240237837544101 0.32402378375441016 0.7382667026916152 -0.4582388295169337 9.023892744153272e-17 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.24104697653084298 -0.24104697653084275 0.8785256666496232 -0.18319568761638738 -0.18319568761638738 0.9371428824013666 -0.25907782599535994 0 0.9371428824013666 -0.34089190337894715 9.023892744153272e-17 0.8785256666496232 -0.24104697653084298 -0.24104697653084275 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.25907782599535994 0 0.9371428824013666 -0.10226757028252298 9.023892744153272e-17 1.0000000000000002 -0.07231409244224378 0.07231409244224396 1.0000000000000002 -0.18319568761638733 0.18319568761638746 0.9371428824013666 -0.25907782599535994 0 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 -0.3696144473933624 0.33346339036844364 0 -0.4854024656044016 0.416085364847598 -0.3432313750335424 -0.3432313750335422 0.416085364847598 -0.2613568821763651 -0.2613568821763649 0.33346339036844364 9.023892744153272e-17 -0.3696144473933624 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.5000000000000003 9.023892744153272e-17 0.5803698541563361 -0.4582388295169337 9.023892744153272e-17 0.7382667026916152 -0.3240237837544101 0.32402378375441016 0.7382667026916152 -0.353553390593274 0.3535533905932741 0.5803698541563361 -0.5000000000000003 9.023892744153272e-17 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.34323137503354223 0.3432313750335425 0.416085364847598 -0.353553390593274 0.3535533905932741 0.5803698541563361 9.023892744153272e-17 0.5000000000000003 0.5803698541563361 9.023892744153272e-17 0.4854024656044017 0.416085364847598 -0.34323137503354223 0.3432313750335425 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.2613568821763651 -0.2613568821763649 0.33346339036844364 -0.3432313750335424 -0.3432313750335422 0.416085364847598 -0.4854024656044017 9.023892744153272e-17 0.416085364847598 -0.3696144473933624 0 0.33346339036844364 -0.2613568821763651 -0.2613568821763649 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.4582388295169337 0 0.7382667026916152 0.3408919033789472 0 0.8785256666496232 0.24104697653084292 -0.24104697653084292 0.8785256666496232 0.32402378375441016 -0.32402378375441016 0.7382667026916152 0.4582388295169337 0 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.08187045275979352 0.08187045275979334 0.3000000000000001 0.2613568821763651 0.2613568821763651 0.33346339036844364 0.36961444739336263 0 0.33346339036844364 0.11578230465052575 0 0.3000000000000001 0.08187045275979352 0.08187045275979334 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.18319568761638738 0.18319568761638738 0.9371428824013666 0.0723140877598673 0.07231408775986721 1.0000000000000002 0.10226756366064253 0 1.0000000000000002 0.25907782599535983 0 0.9371428824013666 0.18319568761638738 0.18319568761638738 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 0.5000000000000003 0.5803698541563361 9.023892744153272e-17 0.4582388295169337 0.7382667026916152 0.32402378375441016 0.32402378375441 0.7382667026916152 0.35355339059327395 0.3535533905932741 0.5803698541563361 9.023892744153272e-17 0.5000000000000003 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>9.023892744153272e-17 0.4854024656044017 0.416085364847598 9.023892744153272e-17 0.5000000000000003 0.5803698541563361 0.35355339059327395 0.3535533905932741 0.5803698541563361 0.3432313750335423 0.3432313750335423 0.416085364847598 9.023892744153272e-17 0.4854024656044017 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.0818704527597928 -0.0818704527597928 0.3000000000000001 -0.2613568821763651 -0.2613568821763649 0.33346339036844364 -0.3696144473933624 0 0.33346339036844364 -0.11578230465052475 0 0.3000000000000001 -0.0818704527597928 -0.0818704527597928 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.24104697653084284 0.24104697653084303 0.8785256666496232 -0.18319568761638733 0.18319568761638746 0.9371428824013666 0 0.25907782599535994 0.9371428824013666 0 0.3408919033789472 0.8785256666496232 -0.24104697653084284 0.24104697653084303 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.32402378375441016 -0.32402378375441 0.7382667026916152 -0.24104697653084298 -0.24104697653084275 0.8785256666496232 -0.34089190337894715 9.023892744153272e-17 0.8785256666496232 -0.4582388295169337 9.023892744153272e-17 0.7382667026916152 -0.32402378375441016 -0.32402378375441 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0 0.36961444739336263 0.33346339036844364 9.023892744153272e-17 0.4854024656044017 0.416085364847598 0.3432313750335423 0.3432313750335423 0.416085364847598 0.2613568821763651 0.2613568821763651 0.33346339036844364 0 0.36961444739336263 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.34089190337894715 9.023892744153272e-17 0.8785256666496232 -0.25907782599535994 0 0.9371428824013666 -0.18319568761638733 0.18319568761638746 0.9371428824013666 -0.24104697653084284 0.24104697653084303 0.8785256666496232 -0.34089190337894715 9.023892744153272e-17 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.32402378375441016 0.32402378375441 0.7382667026916152 0.24104697653084292 0.24104697653084292 0.8785256666496232 0.3408919033789472 0 0.8785256666496232 0.4582388295169337 0 0.7382667026916152 0.32402378375441016 0.32402378375441 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.32402378375441016 -0.32402378375441016 0.7382667026916152 0.24104697653084292 -0.24104697653084292 0.8785256666496232 9.023892744153272e-17 -0.34089190337894715 0.8785256666496232 9.023892744153272e-17 -0.4582388295169337 0.7382667026916152 0.32402378375441016 -0.32402378375441016 0.7382667026916152</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0 -0.4854024656044016 0.416085364847598 9.023892744153272e-17 -0.5000000000000003 0.5803698541563361 -0.3535533905932741 -0.35355339059327395 0.5803698541563361 -0.3432313750335424 -0.3432313750335422 0.416085364847598 0 -0.4854024656044016 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.2613568821763651 -0.26135688217636505 0.33346339036844364 0.3432313750335423 -0.34323137503354234 0.416085364847598 0 -0.4854024656044016 0.416085364847598 9.023892744153272e-17 -0.3696144473933624 0.33346339036844364 0.2613568821763651 -0.26135688217636505 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.11578230465052475 0 0.3000000000000001 -0.3696144473933624 0 0.33346339036844364 -0.261356882176365 0.26135688217636516 0.33346339036844364 -0.0818704527597928 0.08187045275979297 0.3000000000000001 -0.11578230465052475 0 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.5000000000000003 9.023892744153272e-17 0.5803698541563361 0.4582388295169337 0 0.7382667026916152 0.32402378375441016 -0.32402378375441016 0.7382667026916152 0.35355339059327395 -0.35355339059327395 0.5803698541563361 0.5000000000000003 9.023892744153272e-17 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.35355339059327395 -0.35355339059327395 0.5803698541563361 0.32402378375441016 -0.32402378375441016 0.7382667026916152 9.023892744153272e-17 -0.4582388295169337 0.7382667026916152 9.023892744153272e-17 -0.5000000000000003 0.5803698541563361 0.35355339059327395 -0.35355339059327395 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.11578230465052475 0 0.3000000000000001 -0.0818704527597928 0.08187045275979297 0.3000000000000001 2.7071678232459814e-16 0.11578230465052547 0.3000000000000001 0.08187045275979352 0.08187045275979334 0.3000000000000001 0.11578230465052575 0 0.3000000000000001 0.08187045275979352 -0.08187045275979334 0.3000000000000001 1.8047785488306544e-16 -0.11578230465052484 0.3000000000000001 -0.0818704527597928 -0.0818704527597928 0.3000000000000001 -0.11578230465052475 0 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
									<gml:interior>
										<gml:LinearRing>
											<gml:posList>0 -0.019999999999999962 0.3000000000000001 0.014142135623730985 -0.014142135623730895 0.3000000000000001 0.020000000000000052 0 0.3000000000000001 0.014142135623730985 0.014142135623730985 0.3000000000000001 0 0.020000000000000052 0.3000000000000001 -0.014142135623730985 0.014142135623730985 0.3000000000000001 -0.020000000000000052 0 0.3000000000000001 -0.014142135623730985 -0.014142135623730985 0.3000000000000001 0 -0.019999999999999962 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:interior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.3535533905932741 -0.35355339059327395 0.5803698541563361 -0.32402378375441016 -0.32402378375441 0.7382667026916152 -0.4582388295169337 9.023892744153272e-17 0.7382667026916152 -0.5000000000000003 9.023892744153272e-17 0.5803698541563361 -0.3535533905932741 -0.35355339059327395 0.5803698541563361</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.3432313750335423 -0.34323137503354234 0.416085364847598 0.35355339059327395 -0.35355339059327395 0.5803698541563361 9.023892744153272e-17 -0.5000000000000003 0.5803698541563361 0 -0.4854024656044016 0.416085364847598 0.3432313750335423 -0.34323137503354234 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.25907782599535983 0 0.9371428824013666 0.10226756366064253 0 1.0000000000000002 0.0723140877598673 -0.07231408775986721 1.0000000000000002 0.18319568761638738 -0.1831956876163873 0.9371428824013666 0.25907782599535983 0 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.4854024656044017 0 0.416085364847598 0.5000000000000003 9.023892744153272e-17 0.5803698541563361 0.35355339059327395 -0.35355339059327395 0.5803698541563361 0.3432313750335423 -0.34323137503354234 0.416085364847598 0.4854024656044017 0 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.0723140877598673 0.07231408775986721 1.0000000000000002 2.7071678232459814e-16 0.10226756366064235 1.0000000000000002 -0.07231409244224378 0.07231409244224396 1.0000000000000002 -0.10226757028252298 9.023892744153272e-17 1.0000000000000002 -0.07231409244224378 -0.07231409244224378 1.0000000000000002 1.8047785488306544e-16 -0.10226757028252302 1.0000000000000002 0.0723140877598673 -0.07231408775986721 1.0000000000000002 0.10226756366064253 0 1.0000000000000002 0.0723140877598673 0.07231408775986721 1.0000000000000002</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.24104697653084292 0.24104697653084292 0.8785256666496232 0.18319568761638738 0.18319568761638738 0.9371428824013666 0.25907782599535983 0 0.9371428824013666 0.3408919033789472 0 0.8785256666496232 0.24104697653084292 0.24104697653084292 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.18319568761638733 0.18319568761638746 0.9371428824013666 -0.07231409244224378 0.07231409244224396 1.0000000000000002 2.7071678232459814e-16 0.10226756366064235 1.0000000000000002 0 0.25907782599535994 0.9371428824013666 -0.18319568761638733 0.18319568761638746 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.11578230465052575 0 0.3000000000000001 0.36961444739336263 0 0.33346339036844364 0.2613568821763651 -0.26135688217636505 0.33346339036844364 0.08187045275979352 -0.08187045275979334 0.3000000000000001 0.11578230465052575 0 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>1.8047785488306544e-16 -0.11578230465052484 0.3000000000000001 9.023892744153272e-17 -0.3696144473933624 0.33346339036844364 -0.2613568821763651 -0.2613568821763649 0.33346339036844364 -0.0818704527597928 -0.0818704527597928 0.3000000000000001 1.8047785488306544e-16 -0.11578230465052484 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.4854024656044017 9.023892744153272e-17 0.416085364847598 -0.5000000000000003 9.023892744153272e-17 0.5803698541563361 -0.353553390593274 0.3535533905932741 0.5803698541563361 -0.34323137503354223 0.3432313750335425 0.416085364847598 -0.4854024656044017 9.023892744153272e-17 0.416085364847598</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.36961444739336263 0 0.33346339036844364 0.4854024656044017 0 0.416085364847598 0.3432313750335423 -0.34323137503354234 0.416085364847598 0.2613568821763651 -0.26135688217636505 0.33346339036844364 0.36961444739336263 0 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.18319568761638738 -0.18319568761638738 0.9371428824013666 -0.07231409244224378 -0.07231409244224378 1.0000000000000002 -0.10226757028252298 9.023892744153272e-17 1.0000000000000002 -0.25907782599535994 0 0.9371428824013666 -0.18319568761638738 -0.18319568761638738 0.9371428824013666</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.3696144473933624 0 0.33346339036844364 -0.4854024656044017 9.023892744153272e-17 0.416085364847598 -0.34323137503354223 0.3432313750335425 0.416085364847598 -0.261356882176365 0.26135688217636516 0.33346339036844364 -0.3696144473933624 0 0.33346339036844364</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.24104697653084292 -0.24104697653084292 0.8785256666496232 0.18319568761638738 -0.1831956876163873 0.9371428824013666 1.8047785488306544e-16 -0.25907782599535994 0.9371428824013666 9.023892744153272e-17 -0.34089190337894715 0.8785256666496232 0.24104697653084292 -0.24104697653084292 0.8785256666496232</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.014142135623730985 -0.014142135623730895 -9.023892744153272e-17 0 -0.019999999999999962 -9.023892744153272e-17 -0.014142135623730985 -0.014142135623730985 -9.023892744153272e-17 -0.020000000000000052 0 -9.023892744153272e-17 -0.014142135623730985 0.014142135623730985 -9.023892744153272e-17 0 0.020000000000000052 -9.023892744153272e-17 0.014142135623730985 0.014142135623730985 -9.023892744153272e-17 0.020000000000000052 0 -9.023892744153272e-17 0.014142135623730985 -0.014142135623730895 -9.023892744153272e-17</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.014142135623730985 -0.014142135623730895 0.3000000000000001 0 -0.019999999999999962 0.3000000000000001 0 -0.019999999999999962 -9.023892744153272e-17 0.014142135623730985 -0.014142135623730895 -9.023892744153272e-17 0.014142135623730985 -0.014142135623730895 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0 -0.019999999999999962 0.3000000000000001 -0.014142135623730985 -0.014142135623730985 0.3000000000000001 -0.014142135623730985 -0.014142135623730985 -9.023892744153272e-17 0 -0.019999999999999962 -9.023892744153272e-17 0 -0.019999999999999962 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.014142135623730985 -0.014142135623730985 0.3000000000000001 -0.020000000000000052 0 0.3000000000000001 -0.020000000000000052 0 -9.023892744153272e-17 -0.014142135623730985 -0.014142135623730985 -9.023892744153272e-17 -0.014142135623730985 -0.014142135623730985 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.020000000000000052 0 0.3000000000000001 -0.014142135623730985 0.014142135623730985 0.3000000000000001 -0.014142135623730985 0.014142135623730985 -9.023892744153272e-17 -0.020000000000000052 0 -9.023892744153272e-17 -0.020000000000000052 0 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>-0.014142135623730985 0.014142135623730985 0.3000000000000001 0 0.020000000000000052 0.3000000000000001 0 0.020000000000000052 -9.023892744153272e-17 -0.014142135623730985 0.014142135623730985 -9.023892744153272e-17 -0.014142135623730985 0.014142135623730985 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0 0.020000000000000052 0.3000000000000001 0.014142135623730985 0.014142135623730985 0.3000000000000001 0.014142135623730985 0.014142135623730985 -9.023892744153272e-17 0 0.020000000000000052 -9.023892744153272e-17 0 0.020000000000000052 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.014142135623730985 0.014142135623730985 0.3000000000000001 0.020000000000000052 0 0.3000000000000001 0.020000000000000052 0 -9.023892744153272e-17 0.014142135623730985 0.014142135623730985 -9.023892744153272e-17 0.014142135623730985 0.014142135623730985 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
							<gml:geometryMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>0.020000000000000052 0 0.3000000000000001 0.014142135623730985 -0.014142135623730895 0.3000000000000001 0.014142135623730985 -0.014142135623730895 -9.023892744153272e-17 0.020000000000000052 0 -9.023892744153272e-17 0.020000000000000052 0 0.3000000000000001</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:geometryMember>
						</gml:MultiGeometry>
					</core:relativeGMLGeometry>
					<core:referencePoint>
						<gml:Point>
							<gml:pos>396805.48 5819572.33 43.03</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>15.46</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>1.11</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396921.79</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819571.66</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>44.29</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">16.57</veg:height>
			<veg:crownDiameter uom="m">11.73</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>9.18631955174985 -7.100984814328744 0.0 0.0 
10.6704232855655 6.113339076697166 0.0 0.0 
0.0 0.0 16.57 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396921.79 5819571.66 44.29</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>12.22</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>0.19</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396968.94</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819570.08</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.78</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">12.41</veg:height>
			<veg:crownDiameter uom="m">7.09</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>4.202628588550746 -5.240464334988583 0.0 0.0 
6.8424274162533845 3.2187006001976446 0.0 0.0 
0.0 0.0 12.41 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396968.94 5819570.08 43.78</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>12.69</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>0.42</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396960</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819567.37</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.74</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">13.11</veg:height>
			<veg:crownDiameter uom="m">10.58</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>8.879241131576089 -6.1382900759350125 0.0 0.0 
8.439287702604254 6.458288855701466 0.0 0.0 
0.0 0.0 13.11 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396960 5819567.37 43.74</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>3.59</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>2.31</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396855.07</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819568.35</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.11</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">5.9</veg:height>
			<veg:crownDiameter uom="m">2.99</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>-3.0502743977388693 -1.1895169640505043 0.0 0.0 
1.633225672862994 -2.2215871336132804 0.0 0.0 
0.0 0.0 5.9 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-c879065e-0344-4584-aab5-e3ea51c2af20"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396855.07 5819568.35 43.11</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>3.35</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>0.2</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396913.16</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819568.95</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.31</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">3.55</veg:height>
			<veg:crownDiameter uom="m">3.61</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>-3.083141819660793 -2.041581633572613 0.0 0.0 
2.8814295965472994 -2.1845009575321734 0.0 0.0 
0.0 0.0 3.55 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396913.16 5819568.95 43.31</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>17.6</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>1.23</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396996.72</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819570.21</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>44.18</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">18.83</veg:height>
			<veg:crownDiameter uom="m">11.49</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>-2.3873302463581 -6.833228283092487 0.0 0.0 
15.881569642035505 -1.027176338875123 0.0 0.0 
0.0 0.0 18.83 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-5fd72b80-96e1-437e-9b79-8a7052b5a826"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396996.72 5819570.21 44.18</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<veg:SolitaryVegetationObject>
			<gen:doubleAttribute name="h_crown">
				<gen:value>2.36</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="h_trunk">
				<gen:value>1.07</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="X">
				<gen:value>396898.18</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Y">
				<gen:value>5819567.25</gen:value>
			</gen:doubleAttribute>
			<gen:doubleAttribute name="Z">
				<gen:value>43.28</gen:value>
			</gen:doubleAttribute>
			<veg:height uom="m">3.43</veg:height>
			<veg:crownDiameter uom="m">2.5700000000000003</veg:crownDiameter>
			<veg:lod2ImplicitRepresentation>
				<core:ImplicitGeometry>
					<core:transformationMatrix>1.4845780276697156 -1.7200562140320053 0.0 0.0 
2.846072395382854 0.8972216117380835 0.0 0.0 
0.0 0.0 3.43 0.0 
0.0 0.0 0.0 1.0 </core:transformationMatrix>
					<core:relativeGMLGeometry xlink:href="#fme-gen-9749d372-fda4-40fc-8a08-c90d60053563"/>
					<core:referencePoint>
						<gml:Point srsName="EPSG:25833" srsDimension="3">
							<gml:pos>396898.18 5819567.25 43.28</gml:pos>
						</gml:Point>
					</core:referencePoint>
				</core:ImplicitGeometry>
			</veg:lod2ImplicitRepresentation>
		</veg:SolitaryVegetationObject>
	</core:cityObjectMember>
</core:CityModel>