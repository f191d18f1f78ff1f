<?xml version='1.0' encoding='UTF-8'?>
<core:CityModel xmlns:brid="http://www.opengis.net/citygml/bridge/2.0" xmlns:tran="http://www.opengis.net/citygml/transportation/2.0" xmlns:frn="http://www.opengis.net/citygml/cityfurniture/2.0" xmlns:wtr="http://www.opengis.net/citygml/waterbody/2.0" xmlns:sch="http://www.ascc.net/xml/schematron" xmlns:veg="http://www.opengis.net/citygml/vegetation/2.0" xmlns:xlink="http://www.w3.org/1999/xlink" xmlns:tun="http://www.opengis.net/citygml/tunnel/2.0" xmlns:tex="http://www.opengis.net/citygml/texturedsurface/2.0" xmlns:gml="http://www.opengis.net/gml" xmlns:app="http://www.opengis.net/citygml/appearance/2.0" xmlns:gen="http://www.opengis.net/citygml/generics/2.0" xmlns:dem="http://www.opengis.net/citygml/relief/2.0" xmlns:luse="http://www.opengis.net/citygml/landuse/2.0" xmlns:uro="https://www.geospatial.jp/iur/uro/3.0" xmlns:xAL="urn:oasis:names:tc:ciq:xsdschema:xAL:2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:smil20="http://www.w3.org/2001/SMIL20/" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xmlns:smil20lang="http://www.w3.org/2001/SMIL20/Language" xmlns:pbase="http://www.opengis.net/citygml/profiles/base/2.0" xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:grp="http://www.opengis.net/citygml/cityobjectgroup/2.0" xsi:schemaLocation="https://www.geospatial.jp/iur/uro/3.0 ../../schemas/iur/uro/3.0/urbanObject.xsd  http://www.opengis.net/citygml/2.0 http://schemas.opengis.net/citygml/2.0/cityGMLBase.xsd http://www.opengis.net/citygml/landuse/2.0 http://schemas.opengis.net/citygml/landuse/2.0/landUse.xsd  http://www.opengis.net/citygml/building/2.0 http://schemas.opengis.net/citygml/building/2.0/building.xsd  http://www.opengis.net/citygml/transportation/2.0 http://schemas.opengis.net/citygml/transportation/2.0/transportation.xsd  http://www.opengis.net/citygml/generics/2.0 http://schemas.opengis.net/citygml/generics/2.0/generics.xsd  http://www.opengis.net/citygml/relief/2.0 http://schemas.opengis.net/citygml/relief/2.0/relief.xsd  http://www.opengis.net/citygml/cityobjectgroup/2.0 http://schemas.opengis.net/citygml/cityobjectgroup/2.0/cityObjectGroup.xsd  http://www.opengis.net/gml http://schemas.opengis.net/gml/3.1.1/base/gml.xsd http://www.opengis.net/citygml/appearance/2.0 http://schemas.opengis.net/citygml/appearance/2.0/appearance.xsd">
	<gml:boundedBy>
		<gml:Envelope srsName="http://www.opengis.net/def/crs/EPSG/0/6697" srsDimension="3">
			<gml:lowerCorner>34.6666407 135.3891737558797 0</gml:lowerCorner>
			<gml:upperCorner>34.67180265 135.39984961 16.66477569</gml:upperCorner>
		</gml:Envelope>
	</gml:boundedBy>
	<core:cityObjectMember>
		<bldg:Building gml:id="bldg_f5f2099a-006d-4b73-be32-dff49daec8af">
			<core:creationDate>2023-03-22</core:creationDate>
			<bldg:class codeSpace="../../codelists/Building_class.xml">3003</bldg:class>
			<bldg:measuredHeight uom="m">2.5</bldg:measuredHeight>
			<bldg:lod0FootPrint>
				<gml:MultiSurface>
					<gml:surfaceMember>
						<gml:Polygon>
							<gml:exterior>
								<gml:LinearRing>
									<gml:posList>34.66841135 135.39984961 0 34.66841681 135.39981372 0 34.66839985 135.3998103 0 34.6683944 135.39984619 0 34.66841135 135.39984961 0 </gml:posList>
								</gml:LinearRing>
							</gml:exterior>
						</gml:Polygon>
					</gml:surfaceMember>
				</gml:MultiSurface>
			</bldg:lod0FootPrint>
			<bldg:lod1Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66841135 135.39984961 7.356 34.6683944 135.39984619 7.356 34.66839985 135.3998103 7.356 34.66841681 135.39981372 7.356 34.66841135 135.39984961 7.356</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66841135 135.39984961 7.356 34.66841681 135.39981372 7.356 34.66841681 135.39981372 9.75 34.66841135 135.39984961 9.75 34.66841135 135.39984961 7.356</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66841681 135.39981372 7.356 34.66839985 135.3998103 7.356 34.66839985 135.3998103 9.75 34.66841681 135.39981372 9.75 34.66841681 135.39981372 7.356</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66839985 135.3998103 7.356 34.6683944 135.39984619 7.356 34.6683944 135.39984619 9.75 34.66839985 135.3998103 9.75 34.66839985 135.3998103 7.356</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.6683944 135.39984619 7.356 34.66841135 135.39984961 7.356 34.66841135 135.39984961 9.75 34.6683944 135.39984619 9.75 34.6683944 135.39984619 7.356</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66841135 135.39984961 9.75 34.66841681 135.39981372 9.75 34.66839985 135.3998103 9.75 34.6683944 135.39984619 9.75 34.66841135 135.39984961 9.75</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod1Solid>
			<bldg:lod2Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember xlink:href="#poly_OSK0214_p723_0"/>
							<gml:surfaceMember xlink:href="#poly_OSK0214_p723_1"/>
							<gml:surfaceMember xlink:href="#poly_OSK0214_p723_2"/>
							<gml:surfaceMember xlink:href="#poly_OSK0214_p723_3"/>
							<gml:surfaceMember xlink:href="#poly_OSK0214_p723_4"/>
							<gml:surfaceMember xlink:href="#poly_OSK0214_b_0"/>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod2Solid>
			<bldg:boundedBy>
				<bldg:GroundSurface gml:id="gnd_OSK0214_b_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0214_b_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0214_b_0">
											<gml:posList>34.66841681176711 135.39981372113283 7.34960233 34.66841135477192 135.39984960747154 7.34981293 34.668394396612484 135.39984618988032 7.34953111 34.66839985234066 135.39981030343662 7.34932047 34.66841681176711 135.39981372113283 7.34960233</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:GroundSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:RoofSurface gml:id="roof_OSK0214_p723_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0214_p723_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0214_p723_0">
											<gml:posList>34.668394393554244 135.39984618743355 9.86605116 34.66841135170701 135.3998496050234 9.86633298 34.66841680869992 135.3998137186988 9.86612238 34.66839984928024 135.3998103010041 9.86584052 34.668394393554244 135.39984618743355 9.86605116</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:RoofSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0214_p723_1">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0214_p723_1">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0214_p723_1">
											<gml:posList>34.66839984928024 135.3998103010041 9.86584052 34.66841680869992 135.3998137186988 9.86612238 34.66841681176711 135.39981372113283 7.34960233 34.66839985234066 135.39981030343662 7.34932047 34.66839984928024 135.3998103010041 9.86584052</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0214_p723_4">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0214_p723_4">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0214_p723_4">
											<gml:posList>34.668394393554244 135.39984618743355 9.86605116 34.66839984928024 135.3998103010041 9.86584052 34.66839985234066 135.39981030343662 7.34932047 34.668394396612484 135.39984618988032 7.34953111 34.668394393554244 135.39984618743355 9.86605116</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0214_p723_3">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0214_p723_3">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0214_p723_3">
											<gml:posList>34.66841135170701 135.3998496050234 9.86633298 34.668394393554244 135.39984618743355 9.86605116 34.668394396612484 135.39984618988032 7.34953111 34.66841135477192 135.39984960747154 7.34981293 34.66841135170701 135.3998496050234 9.86633298</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0214_p723_2">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0214_p723_2">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0214_p723_2">
											<gml:posList>34.66841680869992 135.3998137186988 9.86612238 34.66841135170701 135.3998496050234 9.86633298 34.66841135477192 135.39984960747154 7.34981293 34.66841681176711 135.39981372113283 7.34960233 34.66841680869992 135.3998137186988 9.86612238</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<uro:buildingDataQualityAttribute>
				<uro:BuildingDataQualityAttribute>
					<uro:srcScale codeSpace="../../codelists/BuildingDataQualityAttribute_srcScale.xml">1</uro:srcScale>
					<uro:geometrySrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_geometrySrcDesc.xml">5</uro:geometrySrcDesc>
					<uro:thematicSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_thematicSrcDesc.xml">1</uro:thematicSrcDesc>
					<uro:appearanceSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_appearanceSrcDesc.xml">1</uro:appearanceSrcDesc>
					<uro:lod1HeightType codeSpace="../../codelists/BuildingDataQualityAttribute_lod1HeightType.xml">2</uro:lod1HeightType>
					<uro:lodType>2.0</uro:lodType>
				</uro:BuildingDataQualityAttribute>
			</uro:buildingDataQualityAttribute>
			<uro:buildingDetailAttribute>
				<uro:BuildingDetailAttribute>
					<uro:specifiedBuildingCoverageRate>0.6</uro:specifiedBuildingCoverageRate>
					<uro:surveyYear>2021</uro:surveyYear>
				</uro:BuildingDetailAttribute>
			</uro:buildingDetailAttribute>
			<uro:buildingIDAttribute>
				<uro:BuildingIDAttribute>
					<uro:buildingID>27100-bldg-399325</uro:buildingID>
					<uro:prefecture codeSpace="../../codelists/Common_localPublicAuthorities.xml">27</uro:prefecture>
					<uro:city codeSpace="../../codelists/Common_localPublicAuthorities.xml">27104</uro:city>
				</uro:BuildingIDAttribute>
			</uro:buildingIDAttribute>
		</bldg:Building>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<bldg:Building gml:id="bldg_c4d4d206-9799-49b5-aca0-68ee140f21ed">
			<core:creationDate>2023-03-22</core:creationDate>
			<bldg:class codeSpace="../../codelists/Building_class.xml">3003</bldg:class>
			<bldg:measuredHeight uom="m">4</bldg:measuredHeight>
			<bldg:lod0FootPrint>
				<gml:MultiSurface>
					<gml:surfaceMember>
						<gml:Polygon>
							<gml:exterior>
								<gml:LinearRing>
									<gml:posList>34.66719918 135.39585891 0 34.6672086 135.39579579 0 34.66715713 135.39578448 0 34.66714771 135.39584761 0 34.66719918 135.39585891 0 </gml:posList>
								</gml:LinearRing>
							</gml:exterior>
						</gml:Polygon>
					</gml:surfaceMember>
				</gml:MultiSurface>
			</bldg:lod0FootPrint>
			<bldg:lod1Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66719918 135.39585891 6.596 34.66714771 135.39584761 6.596 34.66715713 135.39578448 6.596 34.6672086 135.39579579 6.596 34.66719918 135.39585891 6.596</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66719918 135.39585891 6.596 34.6672086 135.39579579 6.596 34.6672086 135.39579579 9.604 34.66719918 135.39585891 9.604 34.66719918 135.39585891 6.596</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.6672086 135.39579579 6.596 34.66715713 135.39578448 6.596 34.66715713 135.39578448 9.604 34.6672086 135.39579579 9.604 34.6672086 135.39579579 6.596</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66715713 135.39578448 6.596 34.66714771 135.39584761 6.596 34.66714771 135.39584761 9.604 34.66715713 135.39578448 9.604 34.66715713 135.39578448 6.596</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66714771 135.39584761 6.596 34.66719918 135.39585891 6.596 34.66719918 135.39585891 9.604 34.66714771 135.39584761 9.604 34.66714771 135.39584761 6.596</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66719918 135.39585891 9.604 34.6672086 135.39579579 9.604 34.66715713 135.39578448 9.604 34.66714771 135.39584761 9.604 34.66719918 135.39585891 9.604</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod1Solid>
			<bldg:lod2Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember xlink:href="#poly_OSK0255_p781_0"/>
							<gml:surfaceMember xlink:href="#poly_OSK0255_p781_1"/>
							<gml:surfaceMember xlink:href="#poly_OSK0255_p781_2"/>
							<gml:surfaceMember xlink:href="#poly_OSK0255_p781_3"/>
							<gml:surfaceMember xlink:href="#poly_OSK0255_p781_4"/>
							<gml:surfaceMember xlink:href="#poly_OSK0255_b_0"/>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod2Solid>
			<bldg:boundedBy>
				<bldg:GroundSurface gml:id="gnd_OSK0255_b_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0255_b_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0255_b_0">
											<gml:posList>34.66714771584894 135.39584760763543 6.58175113 34.667157137241944 135.3957844851908 6.58168855 34.667208603459045 135.3957957863739 6.58236954 34.6671991831478 135.395858908732 6.58243214 34.66714771584894 135.39584760763543 6.58175113</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:GroundSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:RoofSurface gml:id="roof_OSK0255_p781_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0255_p781_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0255_p781_0">
											<gml:posList>34.66720859932867 135.39579578501738 10.59738907 34.667157134131635 135.3957844841667 9.62912379 34.667147712787965 135.39584760659642 9.5852245 34.6671991790685 135.39585890735125 10.5535095 34.66720859932867 135.39579578501738 10.59738907</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:RoofSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0255_p781_4">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0255_p781_4">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0255_p781_4">
											<gml:posList>34.66720859932867 135.39579578501738 10.59738907 34.6671991790685 135.39585890735125 10.5535095 34.6671991831478 135.395858908732 6.58243214 34.667208603459045 135.3957957863739 6.58236954 34.66720859932867 135.39579578501738 10.59738907</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0255_p781_2">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0255_p781_2">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0255_p781_2">
											<gml:posList>34.667147712787965 135.39584760659642 9.5852245 34.667157134131635 135.3957844841667 9.62912379 34.667157137241944 135.3957844851908 6.58168855 34.66714771584894 135.39584760763543 6.58175113 34.667147712787965 135.39584760659642 9.5852245</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0255_p781_3">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0255_p781_3">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0255_p781_3">
											<gml:posList>34.667157134131635 135.3957844841667 9.62912379 34.66720859932867 135.39579578501738 10.59738907 34.667208603459045 135.3957957863739 6.58236954 34.667157137241944 135.3957844851908 6.58168855 34.667157134131635 135.3957844841667 9.62912379</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0255_p781_1">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0255_p781_1">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0255_p781_1">
											<gml:posList>34.6671991790685 135.39585890735125 10.5535095 34.667147712787965 135.39584760659642 9.5852245 34.66714771584894 135.39584760763543 6.58175113 34.6671991831478 135.395858908732 6.58243214 34.6671991790685 135.39585890735125 10.5535095</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<uro:buildingDataQualityAttribute>
				<uro:BuildingDataQualityAttribute>
					<uro:srcScale codeSpace="../../codelists/BuildingDataQualityAttribute_srcScale.xml">1</uro:srcScale>
					<uro:geometrySrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_geometrySrcDesc.xml">5</uro:geometrySrcDesc>
					<uro:thematicSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_thematicSrcDesc.xml">1</uro:thematicSrcDesc>
					<uro:appearanceSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_appearanceSrcDesc.xml">1</uro:appearanceSrcDesc>
					<uro:lod1HeightType codeSpace="../../codelists/BuildingDataQualityAttribute_lod1HeightType.xml">2</uro:lod1HeightType>
					<uro:lodType>2.0</uro:lodType>
				</uro:BuildingDataQualityAttribute>
			</uro:buildingDataQualityAttribute>
			<uro:buildingDetailAttribute>
				<uro:BuildingDetailAttribute>
					<uro:specifiedBuildingCoverageRate>0.6</uro:specifiedBuildingCoverageRate>
					<uro:surveyYear>2021</uro:surveyYear>
				</uro:BuildingDetailAttribute>
			</uro:buildingDetailAttribute>
			<uro:buildingIDAttribute>
				<uro:BuildingIDAttribute>
					<uro:buildingID>27100-bldg-950257</uro:buildingID>
					<uro:prefecture codeSpace="../../codelists/Common_localPublicAuthorities.xml">27</uro:prefecture>
					<uro:city codeSpace="../../codelists/Common_localPublicAuthorities.xml">27104</uro:city>
				</uro:BuildingIDAttribute>
			</uro:buildingIDAttribute>
		</bldg:Building>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<bldg:Building gml:id="bldg_cbdcdb1a-8757-4dd3-8dad-7911eef8fff5">
			<core:creationDate>2023-03-22</core:creationDate>
			<gen:intAttribute name="1/2500図郭">
				<gen:value>054</gen:value>
			</gen:intAttribute>
			<gen:stringAttribute name="区名">
				<gen:value>此花区</gen:value>
			</gen:stringAttribute>
			<gen:stringAttribute name="町丁目名称">
				<gen:value>北港緑地２丁目</gen:value>
			</gen:stringAttribute>
			<gen:intAttribute name="街区番号">
				<gen:value>1</gen:value>
			</gen:intAttribute>
			<bldg:class codeSpace="../../codelists/Building_class.xml">3003</bldg:class>
			<bldg:usage codeSpace="../../codelists/Building_usage.xml">402</bldg:usage>
			<bldg:measuredHeight uom="m">3.8</bldg:measuredHeight>
			<bldg:storeysAboveGround>1</bldg:storeysAboveGround>
			<bldg:lod0FootPrint>
				<gml:MultiSurface>
					<gml:surfaceMember>
						<gml:Polygon>
							<gml:exterior>
								<gml:LinearRing>
									<gml:posList>34.66776683 135.39563435 0 34.66777531 135.39557131 0 34.66767619 135.39555184 0 34.66766771 135.39561487 0 34.66776683 135.39563435 0 </gml:posList>
								</gml:LinearRing>
							</gml:exterior>
						</gml:Polygon>
					</gml:surfaceMember>
				</gml:MultiSurface>
			</bldg:lod0FootPrint>
			<bldg:lod1Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66776683 135.39563435 6.964 34.66766771 135.39561487 6.964 34.66767619 135.39555184 6.964 34.66777531 135.39557131 6.964 34.66776683 135.39563435 6.964</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66776683 135.39563435 6.964 34.66777531 135.39557131 6.964 34.66777531 135.39557131 10.095 34.66776683 135.39563435 10.095 34.66776683 135.39563435 6.964</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66777531 135.39557131 6.964 34.66767619 135.39555184 6.964 34.66767619 135.39555184 10.095 34.66777531 135.39557131 10.095 34.66777531 135.39557131 6.964</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66767619 135.39555184 6.964 34.66766771 135.39561487 6.964 34.66766771 135.39561487 10.095 34.66767619 135.39555184 10.095 34.66767619 135.39555184 6.964</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66766771 135.39561487 6.964 34.66776683 135.39563435 6.964 34.66776683 135.39563435 10.095 34.66766771 135.39561487 10.095 34.66766771 135.39561487 6.964</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66776683 135.39563435 10.095 34.66777531 135.39557131 10.095 34.66767619 135.39555184 10.095 34.66766771 135.39561487 10.095 34.66776683 135.39563435 10.095</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod1Solid>
			<bldg:lod2Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember xlink:href="#poly_OSK0233_p750_0"/>
							<gml:surfaceMember xlink:href="#poly_OSK0233_p750_1"/>
							<gml:surfaceMember xlink:href="#poly_OSK0233_p750_2"/>
							<gml:surfaceMember xlink:href="#poly_OSK0233_p750_3"/>
							<gml:surfaceMember xlink:href="#poly_OSK0233_p750_4"/>
							<gml:surfaceMember xlink:href="#poly_OSK0233_b_0"/>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod2Solid>
			<bldg:boundedBy>
				<bldg:GroundSurface gml:id="gnd_OSK0233_b_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0233_b_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0233_b_0">
											<gml:posList>34.66767619258458 135.3955518367269 6.94486571 34.6677753070608 135.39557130876238 6.94626901 34.66776683131628 135.39563434651097 6.94631538 34.66766771642886 135.3956148749831 6.94491209 34.66767619258458 135.3955518367269 6.94486571</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:GroundSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:RoofSurface gml:id="roof_OSK0233_p750_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0233_p750_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0233_p750_0">
											<gml:posList>34.667766827086766 135.3956343453269 10.73431688 34.66777530380821 135.39557130788168 9.85589453 34.667676189412965 135.39555183586484 9.82217551 34.667667712293934 135.39561487382065 10.70060676 34.667766827086766 135.3956343453269 10.73431688</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:RoofSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0233_p750_4">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0233_p750_4">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0233_p750_4">
											<gml:posList>34.667766827086766 135.3956343453269 10.73431688 34.667667712293934 135.39561487382065 10.70060676 34.66766771642886 135.3956148749831 6.94491209 34.66776683131628 135.39563434651097 6.94631538 34.667766827086766 135.3956343453269 10.73431688</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0233_p750_3">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0233_p750_3">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0233_p750_3">
											<gml:posList>34.66777530380821 135.39557130788168 9.85589453 34.667766827086766 135.3956343453269 10.73431688 34.66776683131628 135.39563434651097 6.94631538 34.6677753070608 135.39557130876238 6.94626901 34.66777530380821 135.39557130788168 9.85589453</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0233_p750_1">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0233_p750_1">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0233_p750_1">
											<gml:posList>34.667667712293934 135.39561487382065 10.70060676 34.667676189412965 135.39555183586484 9.82217551 34.66767619258458 135.3955518367269 6.94486571 34.66766771642886 135.3956148749831 6.94491209 34.667667712293934 135.39561487382065 10.70060676</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0233_p750_2">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0233_p750_2">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0233_p750_2">
											<gml:posList>34.667676189412965 135.39555183586484 9.82217551 34.66777530380821 135.39557130788168 9.85589453 34.6677753070608 135.39557130876238 6.94626901 34.66767619258458 135.3955518367269 6.94486571 34.667676189412965 135.39555183586484 9.82217551</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<uro:buildingDataQualityAttribute>
				<uro:BuildingDataQualityAttribute>
					<uro:srcScale codeSpace="../../codelists/BuildingDataQualityAttribute_srcScale.xml">1</uro:srcScale>
					<uro:geometrySrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_geometrySrcDesc.xml">5</uro:geometrySrcDesc>
					<uro:thematicSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_thematicSrcDesc.xml">1</uro:thematicSrcDesc>
					<uro:appearanceSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_appearanceSrcDesc.xml">1</uro:appearanceSrcDesc>
					<uro:lod1HeightType codeSpace="../../codelists/BuildingDataQualityAttribute_lod1HeightType.xml">2</uro:lod1HeightType>
					<uro:lodType>2.0</uro:lodType>
				</uro:BuildingDataQualityAttribute>
			</uro:buildingDataQualityAttribute>
			<uro:buildingDetailAttribute>
				<uro:BuildingDetailAttribute>
					<uro:buildingRoofEdgeArea uom="m2">76.3816812314</uro:buildingRoofEdgeArea>
					<uro:buildingStructureType codeSpace="../../codelists/BuildingDetailAttribute_buildingStructureType.xml">601</uro:buildingStructureType>
					<uro:buildingStructureOrgType codeSpace="../../codelists/BuildingDetailAttribute_buildingStructureOrgType.xml">1</uro:buildingStructureOrgType>
					<uro:detailedUsage codeSpace="../../codelists/BuildingDetailAttribute_detailedUsage.xml">1418</uro:detailedUsage>
					<uro:groundFloorUsage codeSpace="../../codelists/BuildingDetailAttribute_groundFloorUsage.xml">1418</uro:groundFloorUsage>
					<uro:specifiedBuildingCoverageRate>0.6</uro:specifiedBuildingCoverageRate>
					<uro:surveyYear>2021</uro:surveyYear>
				</uro:BuildingDetailAttribute>
			</uro:buildingDetailAttribute>
			<uro:buildingIDAttribute>
				<uro:BuildingIDAttribute>
					<uro:buildingID>27100-bldg-950251</uro:buildingID>
					<uro:prefecture codeSpace="../../codelists/Common_localPublicAuthorities.xml">27</uro:prefecture>
					<uro:city codeSpace="../../codelists/Common_localPublicAuthorities.xml">27104</uro:city>
				</uro:BuildingIDAttribute>
			</uro:buildingIDAttribute>
			<uro:keyValuePairAttribute>
				<uro:KeyValuePairAttribute>
					<uro:key codeSpace="../../codelists/KeyValuePairAttribute_key.xml">100</uro:key>
					<uro:codeValue codeSpace="../../codelists/KeyValuePairAttribute_key100.xml">27104</uro:codeValue>
				</uro:KeyValuePairAttribute>
			</uro:keyValuePairAttribute>
			<uro:keyValuePairAttribute>
				<uro:KeyValuePairAttribute>
					<uro:key codeSpace="../../codelists/KeyValuePairAttribute_key.xml">101</uro:key>
					<uro:codeValue codeSpace="../../codelists/KeyValuePairAttribute_key101.xml">10405802</uro:codeValue>
				</uro:KeyValuePairAttribute>
			</uro:keyValuePairAttribute>
			<uro:keyValuePairAttribute>
				<uro:KeyValuePairAttribute>
					<uro:key codeSpace="../../codelists/KeyValuePairAttribute_key.xml">104</uro:key>
					<uro:codeValue codeSpace="../../codelists/KeyValuePairAttribute_key104.xml">1418</uro:codeValue>
				</uro:KeyValuePairAttribute>
			</uro:keyValuePairAttribute>
		</bldg:Building>
	</core:cityObjectMember>
	<core:cityObjectMember>
		<bldg:Building gml:id="bldg_c20bf61b-30a0-4b94-8042-04cac85c4176">
			<core:creationDate>2023-03-22</core:creationDate>
			<bldg:class codeSpace="../../codelists/Building_class.xml">3001</bldg:class>
			<bldg:measuredHeight uom="m">4</bldg:measuredHeight>
			<bldg:lod0FootPrint>
				<gml:MultiSurface>
					<gml:surfaceMember>
						<gml:Polygon>
							<gml:exterior>
								<gml:LinearRing>
									<gml:posList>34.66776837 135.39471246 0 34.6677057 135.39474825 0 34.66778989 135.3949642 0 34.66785257 135.39492841 0 34.66776837 135.39471246 0 </gml:posList>
								</gml:LinearRing>
							</gml:exterior>
						</gml:Polygon>
					</gml:surfaceMember>
				</gml:MultiSurface>
			</bldg:lod0FootPrint>
			<bldg:lod1Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66776837 135.39471246 12.654 34.66785257 135.39492841 12.654 34.66778989 135.3949642 12.654 34.6677057 135.39474825 12.654 34.66776837 135.39471246 12.654</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66776837 135.39471246 12.654 34.6677057 135.39474825 12.654 34.6677057 135.39474825 16.369 34.66776837 135.39471246 16.369 34.66776837 135.39471246 12.654</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.6677057 135.39474825 12.654 34.66778989 135.3949642 12.654 34.66778989 135.3949642 16.369 34.6677057 135.39474825 16.369 34.6677057 135.39474825 12.654</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66778989 135.3949642 12.654 34.66785257 135.39492841 12.654 34.66785257 135.39492841 16.369 34.66778989 135.3949642 16.369 34.66778989 135.3949642 12.654</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66785257 135.39492841 12.654 34.66776837 135.39471246 12.654 34.66776837 135.39471246 16.369 34.66785257 135.39492841 16.369 34.66785257 135.39492841 12.654</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
							<gml:surfaceMember>
								<gml:Polygon>
									<gml:exterior>
										<gml:LinearRing>
											<gml:posList>34.66776837 135.39471246 16.369 34.6677057 135.39474825 16.369 34.66778989 135.3949642 16.369 34.66785257 135.39492841 16.369 34.66776837 135.39471246 16.369</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod1Solid>
			<bldg:lod2Solid>
				<gml:Solid>
					<gml:exterior>
						<gml:CompositeSurface>
							<gml:surfaceMember xlink:href="#poly_OSK0880_p1929_0"/>
							<gml:surfaceMember xlink:href="#poly_OSK0880_p1929_1"/>
							<gml:surfaceMember xlink:href="#poly_OSK0880_p1929_2"/>
							<gml:surfaceMember xlink:href="#poly_OSK0880_p1929_3"/>
							<gml:surfaceMember xlink:href="#poly_OSK0880_p1929_4"/>
							<gml:surfaceMember xlink:href="#poly_OSK0880_b_0"/>
						</gml:CompositeSurface>
					</gml:exterior>
				</gml:Solid>
			</bldg:lod2Solid>
			<bldg:boundedBy>
				<bldg:GroundSurface gml:id="gnd_OSK0880_b_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0880_b_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0880_b_0">
											<gml:posList>34.66776837146607 135.39471245550737 12.66944699 34.66785256617504 135.39492840677391 12.67094676 34.66778989393396 135.3949642011004 12.67014056 34.66770570047432 135.39474825195688 12.66864086 34.66776837146607 135.39471245550737 12.66944699</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:GroundSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:RoofSurface gml:id="roof_OSK0880_p1929_0">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0880_p1929_0">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0880_p1929_0">
											<gml:posList>34.66778988946099 135.39496420027146 16.66317021 34.6678525616627 135.39492840596742 16.6639764 34.667768367006595 135.39471245483594 16.66247663 34.66770569605432 135.39474825126308 16.66167051 34.66778988946099 135.39496420027146 16.66317021</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:RoofSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0880_p1929_3">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0880_p1929_3">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0880_p1929_3">
											<gml:posList>34.6678525616627 135.39492840596742 16.6639764 34.66778988946099 135.39496420027146 16.66317021 34.66778989393396 135.3949642011004 12.67014056 34.66785256617504 135.39492840677391 12.67094676 34.6678525616627 135.39492840596742 16.6639764</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0880_p1929_4">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0880_p1929_4">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0880_p1929_4">
											<gml:posList>34.66778988946099 135.39496420027146 16.66317021 34.66770569605432 135.39474825126308 16.66167051 34.66770570047432 135.39474825195688 12.66864086 34.66778989393396 135.3949642011004 12.67014056 34.66778988946099 135.39496420027146 16.66317021</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0880_p1929_1">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0880_p1929_1">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0880_p1929_1">
											<gml:posList>34.66770569605432 135.39474825126308 16.66167051 34.667768367006595 135.39471245483594 16.66247663 34.66776837146607 135.39471245550737 12.66944699 34.66770570047432 135.39474825195688 12.66864086 34.66770569605432 135.39474825126308 16.66167051</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<bldg:boundedBy>
				<bldg:WallSurface gml:id="wall_OSK0880_p1929_2">
					<bldg:lod2MultiSurface>
						<gml:MultiSurface>
							<gml:surfaceMember>
								<gml:Polygon gml:id="poly_OSK0880_p1929_2">
									<gml:exterior>
										<gml:LinearRing gml:id="line_OSK0880_p1929_2">
											<gml:posList>34.667768367006595 135.39471245483594 16.66247663 34.6678525616627 135.39492840596742 16.6639764 34.66785256617504 135.39492840677391 12.67094676 34.66776837146607 135.39471245550737 12.66944699 34.667768367006595 135.39471245483594 16.66247663</gml:posList>
										</gml:LinearRing>
									</gml:exterior>
								</gml:Polygon>
							</gml:surfaceMember>
						</gml:MultiSurface>
					</bldg:lod2MultiSurface>
				</bldg:WallSurface>
			</bldg:boundedBy>
			<uro:buildingDataQualityAttribute>
				<uro:BuildingDataQualityAttribute>
					<uro:srcScale codeSpace="../../codelists/BuildingDataQualityAttribute_srcScale.xml">1</uro:srcScale>
					<uro:geometrySrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_geometrySrcDesc.xml">5</uro:geometrySrcDesc>
					<uro:thematicSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_thematicSrcDesc.xml">1</uro:thematicSrcDesc>
					<uro:appearanceSrcDesc codeSpace="../../codelists/BuildingDataQualityAttribute_appearanceSrcDesc.xml">1</uro:appearanceSrcDesc>
					<uro:lod1HeightType codeSpace="../../codelists/BuildingDataQualityAttribute_lod1HeightType.xml">2</uro:lod1HeightType>
					<uro:lodType>2.0</uro:lodType>
				</uro:BuildingDataQualityAttribute>
			</uro:buildingDataQualityAttribute>
			<uro:buildingDetailAttribute>
				<uro:BuildingDetailAttribute>
					<uro:specifiedBuildingCoverageRate>0.6</uro:specifiedBuildingCoverageRate>
					<uro:surveyYear>2021</uro:surveyYear>
				</uro:BuildingDetailAttribute>
			</uro:buildingDetailAttribute>
			<uro:buildingIDAttribute>
				<uro:BuildingIDAttribute>
					<uro:buildingID>27100-bldg-317531</uro:buildingID>
					<uro:prefecture codeSpace="../../codelists/Common_localPublicAuthorities.xml">27</uro:prefecture>
					<uro:city codeSpace="../../codelists/Common_localPublicAuthorities.xml">27104</uro:city>
				</uro:BuildingIDAttribute>
			</uro:buildingIDAttribute>
		</bldg:Building>
	</core:cityObjectMember>
</core:CityModel>
